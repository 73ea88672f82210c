"""deferred-film: an example transparent plugin for the deferred framework.

The material ``film`` is a thin coloured film (cellophane, a stained window): it multiplies
what lies behind it by its tint and adds its own highlight. A product and a sum do not depend
on the order of their terms, so the films of a frame are drawn in any order and need no
sorting: each is one pass blending into the composition with dual-source factors,
``destination x tint + highlight`` (``film/film.frag``). The highlight of a film behind another
is not tinted by the one in front of it: the price of not sorting (the framework's ``glass``
sorts, or weights, for that). The film casts a coloured shadow: its caster draws its tint into
the transmittance maps instead of depth.
"""

from importlib import resources

from pydantic import Field

from deferred.api import (
    COMPOSITE,
    DEPTH,
    Albedo,
    Blend,
    BlinnPhongParams,
    Material,
    ObjectPass,
    Order,
    Phase,
    ShadowCaster,
    Technique,
)

SHADERS = resources.files(__name__) / "shaders"

# colour = source (the highlight) + destination x the second output (the tint)
TINT_AND_ADD = Blend("one", "src1_color", "add", "zero", "one")


class FilmParams(BlinnPhongParams):
    tint: Albedo = Field((0.9, 0.5, 0.2), description="what passes through is multiplied by it")
    specular_intensity: float = Field(0.6, ge=0.0, le=1.0, description="highlight strength")
    specular_exponent: float = Field(64.0, ge=1.0, le=2048.0, description="highlight exponent")


class FilmPasses(Technique):
    """One pass an object, where the opaque scene is lit: the deferred pipeline's material
    phase, the forward pipeline's lit passes. ``transparent`` keeps it out of Forward+'s
    depth pre-pass; it tests the opaque depth and writes none."""

    def passes(self, material, phase, obj):
        if phase not in (Phase.MATERIAL, Phase.FORWARD):
            return []
        return [ObjectPass(f"{obj.label}.film", phase, obj, fragment="film/film.frag",
                           colors=(COMPOSITE,), blend=TINT_AND_ADD, depth=DEPTH,
                           depth_func="lequal", depth_write=False, cull=None,
                           order=Order.VOLUME, transparent=True)]


class FilmShadow(ShadowCaster):
    """No depth: light passes the film, tinted."""

    def draw(self, frame, obj, view):
        pass

    def transmits(self, obj):
        return True

    def draw_transmittance(self, frame, obj, view):
        self.draw_with(frame, obj, view, "film/shadow.frag")


class FilmMaterial(Material):
    name = "film"
    Params = FilmParams
    surface_shader = "film/surface.glsl"
    shader_root = SHADERS
    techniques = (FilmPasses(),)
    shadow = FilmShadow()
