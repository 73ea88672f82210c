"""Revie's deferred fur ("Implementing Fur Using Deferred Shading", GPU Pro 2, chapter 2).

Passes per phase (section 2.4):
- geometry: the base mesh into the G-buffer with anisotropic grain normals (2.4.2, Listing 2.5);
- stipple: the outermost shell into one pixel of every 2x2 tile, rim-bent normals at the
  silhouette (2.3.2, 2.3.4, Listings 2.3 and 2.6), after the screen phase;
- lighting: nothing special, both samples are lit like any pixel (2.4.3);
- material: stipple obliteration, then ``shells`` concentric shells that take their light from
  the light accumulation at the base and stipple samples (2.4.4, Listings 2.1 and 2.2);
- forward: the same fur lit per fragment, for preview and for the benchmark (2.4).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import moderngl
from pydantic import Field

from deferred.errors import InputError
from deferred.gbuffer import ALBEDO_SPECULAR, LINEAR_DEPTH, NORMAL_EXPONENT_ID
from deferred.material import BlinnPhongParams, ForwardLitPass, GBufferPass, Material
from deferred.passes import Phase, RenderPass
from deferred.registry import materials
from deferred.targets import COMPOSITE, LIGHT_ACCUMULATION
from deferred.validation import NonZeroVec3

from .techniques.heightfield import heightfield_texture, load_heightfield, procedural_heightfield
from .techniques.shells import ShellPass
from .techniques.stipple import (
    StippleObliterationPass,
    StipplePass,
    pattern_defines,
    stipple_scene_passes,
)

if TYPE_CHECKING:
    from deferred.frame import Frame
    from deferred.scene import SceneObject

Vec3 = tuple[float, float, float]
FUR_VERTEX = "materials/revie_fur/fur.vert"
BASE_SHELL = {"u_shell_depth": 0.0}
OUTER_SHELL = {"u_shell_depth": 1.0}


class RevieFurParams(BlinnPhongParams):
    fur_length: float = Field(0.15, gt=0.0, le=4.0,
                              description="strand length, object units (x vertex colour alpha)")
    shells: int = Field(16, ge=0, le=256, description="concentric shells in the material phase")
    density: float = Field(6.0, gt=0.0, le=1024.0,
                           description="heightfield repeats across the UV range")
    albedo_base: Vec3 = Field((0.10, 0.06, 0.035), description="albedo at the strand roots")
    albedo_tip: Vec3 = Field((0.78, 0.58, 0.38), description="albedo at the tips (surface)")
    specular_intensity: float = Field(0.25, ge=0.0, le=1.0, description="Blinn-Phong intensity")
    specular_exponent: float = Field(24.0, ge=1.0, le=2048.0, description="Blinn-Phong exponent")
    rim_strength: float = Field(1.5, ge=0.0, le=16.0,
                                description="silhouette normal bending (0 turns it off)")
    rim_falloff: float = Field(3.0, gt=0.0, le=64.0, description="exponent of 1 - N.V")
    anisotropic: bool = Field(True, description="grain normals (highlights across the grain)")
    stipple: bool = Field(True, description="stippled outer shell (rim light, occlusion fix)")
    comb: NonZeroVec3 = Field((0.0, -1.0, 0.0),
                              description="object-space comb where the mesh has no vertex colours")
    comb_strength: float = Field(0.6, ge=0.0, le=8.0, description="how far strands lean")
    heightfield: str | None = Field(None, description="strand height image (R channel)")
    strand_softness: float = Field(0.1, gt=0.0, le=1.0,
                                   description="smoothstep width of the strand fade")
    seed: int = Field(1, ge=0, description="seed of the procedural heightfield")
    occlusion_test: bool = Field(True, description="reject light samples the G-buffer shows "
                                                   "occluded (off: Figure 2.8's error)")


class FurShellPass(ShellPass):
    """Material-phase shells reading light accumulation + G-buffer (shell.frag)."""

    fragment = "materials/revie_fur/shell.frag"
    vertex = FUR_VERTEX
    colors = (COMPOSITE,)
    extra_reads = (LIGHT_ACCUMULATION, ALBEDO_SPECULAR, NORMAL_EXPONENT_ID, LINEAR_DEPTH)


@materials.register
class RevieFurMaterial(Material):
    name = "revie_fur"
    Params = RevieFurParams
    surface_shader = "materials/revie_fur/surface.glsl"
    # pass counts, switches compiled as defines and the heightfield source are not uniforms
    uniform_overrides = {"shells": None, "stipple": None, "occlusion_test": None, "seed": None}

    def check_files(self, where: str | None) -> None:
        if self.params.heightfield is None:
            return
        path = self.resolve_path(self.params.heightfield)
        key = f"{where}.heightfield" if where else "heightfield"
        if not path.is_file():
            raise InputError(f"heightfield image not found: {path}", key)
        try:
            load_heightfield(path)  # unreadable images fail here, before any GL work
        except InputError as exc:
            raise InputError(f"cannot read heightfield image {path.name}: {exc.message}",
                             key) from None

    def defines(self, obj: SceneObject) -> dict[str, str]:
        defines = {**super().defines(obj), **pattern_defines(4)}
        if obj.mesh.has_comb:
            defines["VERTEX_COMB"] = "1"
        if self.params.stipple:
            defines["FUR_STIPPLE"] = "1"
        if self.params.occlusion_test:
            defines["FUR_OCCLUSION_TEST"] = "1"
        return defines

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        return {"u_heightfield": self.heightfield_texture(frame)}

    def heightfield_texture(self, frame: Frame) -> moderngl.Texture:
        if self.params.heightfield is not None:
            path: Path = self.resolve_path(self.params.heightfield)
            return frame.resources.texture(
                ("heightfield", str(path)),
                lambda ctx: heightfield_texture(ctx, load_heightfield(path)))
        seed = self.params.seed
        return frame.resources.texture(
            ("heightfield", seed),
            lambda ctx: heightfield_texture(ctx, procedural_heightfield(seed=seed)))

    # -- passes ------------------------------------------------------------------------------
    @classmethod
    def scene_passes(cls, objects: list[SceneObject], phase: Phase) -> list[RenderPass]:
        stippled = any(obj.material.params.stipple for obj in objects)
        return stipple_scene_passes(phase) if stippled else []

    def geometry_passes(self, obj: SceneObject) -> list[RenderPass]:
        return [GBufferPass(f"{obj.label}.gbuffer", Phase.GEOMETRY, obj, vertex=FUR_VERTEX,
                            constants=BASE_SHELL)]

    def stipple_passes(self, obj: SceneObject) -> list[RenderPass]:
        if not self.params.stipple:
            return []
        return [StipplePass(f"{obj.label}.stipple", Phase.STIPPLE, obj, vertex=FUR_VERTEX,
                            fragment="materials/revie_fur/stipple.frag", constants=OUTER_SHELL)]

    def material_passes(self, obj: SceneObject) -> list[RenderPass]:
        passes: list[RenderPass] = []
        if self.params.stipple:
            passes.append(StippleObliterationPass(f"{obj.label}.stipple_obliteration",
                                                  Phase.MATERIAL, obj, vertex=FUR_VERTEX,
                                                  constants=OUTER_SHELL))
        if self.params.shells > 0:
            passes.append(FurShellPass(f"{obj.label}.shells", Phase.MATERIAL, obj,
                                       count=self.params.shells))
        return passes

    def forward_passes(self, obj: SceneObject) -> list[RenderPass]:
        passes: list[RenderPass] = [ForwardLitPass(f"{obj.label}.forward", Phase.FORWARD, obj,
                                                   vertex=FUR_VERTEX, constants=BASE_SHELL)]
        if self.params.shells > 0:
            passes.append(ShellPass(f"{obj.label}.forward_shells", Phase.FORWARD, obj,
                                    vertex=FUR_VERTEX, colors=(COMPOSITE,),
                                    fragment="materials/revie_fur/forward_shell.frag",
                                    count=self.params.shells))
        return passes
