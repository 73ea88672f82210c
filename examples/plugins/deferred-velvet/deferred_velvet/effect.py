"""The vignette effect: one post pass multiplying the frame toward its corners."""

from pydantic import Field

from deferred.api import FINAL, Effect, EffectParams, FullscreenPass, Order, Phase

from . import SHADERS


class VignetteParams(EffectParams):
    strength: float = Field(0.5, ge=0.0, le=1.0, description="darkening in the corners")
    radius: float = Field(0.6, ge=0.0, le=1.0, description="where the darkening starts")


class Vignette(Effect):
    name = "vignette"
    Params = VignetteParams
    shader_root = SHADERS

    def passes(self, scene, pipeline):
        # Blending "multiply" scales what `final` holds, so the pass needs no copy of it.
        return [FullscreenPass("post.vignette", Phase.POST, "velvet/vignette.frag", {}, (FINAL,),
                               blend="multiply", uniforms=self.uniforms,
                               order=Order.TRANSPARENT)]
