"""The shared fur technique: the parameters every shell fur has, the mip-mapped fur volume its
shells and fins sample (``fur_volume.py``, ``materials/techniques/fur.glsl``), density in world
units, level of detail and self-shadowing. ``revie_fur`` and ``shell_fur`` build on it
(:class:`FurMaterial`): they differ in how fur is lit and shaped, not in how shells are drawn.

- **Density** is strands per square world unit: the volume tiles ``sqrt(density / strands per
  tile)`` times per world unit along the surface, looked up triplanar in the object's axes scaled
  to world size, so charts, seams and poles of an unwrap play no part.
- **Root shell and skin**: the first shell lies on the skin, opaque, root-coloured; the other
  ``n - 1`` sit at the middles of the ``n - 1`` slabs the layer is cut into, each as opaque as
  its slab (``1 - (1 - coverage)^(slices / (n - 1))``). Silva et al.'s shadow factor
  ``gamma(h) = (K - 1 + h) / K`` (``self_shadow`` = K) darkens every shell toward the roots.
- **Self-shadowing**: under a shadowed light, every shell, the root shell (the skin) too,
  takes the light through the fur in front of it instead, from deep opacity maps
  (``self_shadow_density``; ``fur_shadow.FurShadow``, ``lighting/shadows.glsl``).
- **Level of detail**: the shell count follows the fur layer's projected thickness,
  ``n = clamp(pixels / lod_error, min_shells, shells)``, continuous; the depths move with it and
  the outermost fades by the fraction, so a dolly never pops (:func:`shell_count`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import moderngl
import numpy as np
from pydantic import Field, model_validator

from deferred.api import (
    Material,
    MaterialParams,
    Per,
    ReachMotion,
    RenderWork,
    Work,
    WorkObject,
    check_image,
    counted,
)

from .fur_volume import FurPattern, pattern, strand_volume, volume_texture
from .heightfield import (
    HEIGHTFIELD_BYTES_PER_TEXEL,
    HEIGHTFIELD_GPU_BYTES_PER_TEXEL,
    heightfield_volume,
    load_heightfield,
)

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject

# A heightfield image tile counts as this many strands when density converts to tiles per unit.
IMAGE_TILE_STRANDS = 1024
# The cost model's seconds of making a fur volume (0.24-1.5 s by pattern, once a renderer)
FUR_VOLUME_SECONDS = 0.5


class FurParams(MaterialParams):
    """The fur technique's parameters (a mixin of fur materials' parameter models)."""

    fur_length: float = Field(0.15, gt=0.0, le=4.0,
                              description="strand length, object units (x vertex colour alpha)")
    shells: int = Field(16, ge=0, le=256, description="most concentric shells (close up)")
    min_shells: int = Field(2, ge=1, le=256,
                            description="fewest shells (far away; capped at `shells`)")
    lod_error: float = Field(1.0, gt=0.0, le=64.0,
                             description="projected fur thickness per shell, pixels")
    density: float = Field(12000.0, gt=0.0, le=1e7,
                           description="strands per square world unit")
    pattern: Literal["fine", "coarse", "patchy"] = Field(
        "fine", description="built-in strand pattern of the fur volume")
    thickness_base: float | None = Field(None, gt=0.0, le=2.0,
                                         description="strand diameter at the root / spacing "
                                                     "(default: the pattern's)")
    thickness_tip: float | None = Field(None, ge=0.0, le=2.0,
                                        description="strand diameter at the tip / spacing")
    length_variation: float | None = Field(None, ge=0.0, le=1.0,
                                           description="strand lengths vary down to 1 - this")
    heightfield: str | None = Field(None, description="strand height image (R channel) "
                                                      "instead of the pattern")
    strand_softness: float = Field(0.1, gt=0.0, le=1.0,
                                   description="fade of a heightfield strand's tip")
    seed: int = Field(1, ge=0, description="seed of the strand pattern")
    self_shadow: float = Field(2.5, ge=1.0, le=64.0,
                               description="Silva's K_shadow: roots darkened to (K - 1) / K "
                                           "(lights without a shadow)")
    self_shadow_density: float = Field(0.5, ge=0.0, le=64.0,
                                       description="k: a shadowed light reaches the fur as "
                                                   "exp(-k x the optical depth of the fur "
                                                   "in front; deep opacity maps)")
    fins: bool = Field(True, description="fins at silhouette edges (Lengyel 2001)")
    fin_band: float = Field(0.3, gt=0.0, le=1.0,
                            description="|N.V| below which an edge grows a fin")
    shell_range: tuple[float, float] = Field(
        (0.0, 1.0), description="draw only shells at depths in this range (debugging: one "
                                "shell, the roots)")
    debug: Literal["none", "samples", "comb", "shell_count", "single_shell",
                   "opacity_shadow"] = Field(
        "none", description="debug view instead of the fur (see FUR_DEBUG_VIEWS)")

    @model_validator(mode="after")
    def _check_fur(self) -> FurParams:
        low, high = self.shell_range
        if not 0.0 <= low <= high <= 1.0:
            raise ValueError("shell_range must be two depths 0 <= low <= high <= 1")
        return self


# Fields of FurParams that are not uniforms as they stand.
FUR_UNIFORM_OVERRIDES: dict[str, Any] = {
    "shells": None, "min_shells": None, "lod_error": None, "pattern": None,
    "thickness_base": None, "thickness_tip": None, "length_variation": None, "seed": None,
    "strand_softness": None, "fins": None, "fin_band": None, "shell_range": None,
    "density": None, "debug": None,
}


# Debug views of the fur technique (``deferred render --view <material>.<name>``), like the fur
# debug switches of Lumberyard's legacy renderer: what each shows, and the parameters it sets.
FUR_DEBUG_VIEWS: dict[str, tuple[str, dict[str, Any]]] = {
    "samples": ("light samples each shell and fin fragment used: green base, blue outer "
                "(stipple), cyan both, yellow its own pixel, red none; white in the forward "
                "pipeline, which lights every fragment", {"debug": "samples"}),
    "comb": ("comb direction x lean on the skin, view space (x red, y green, z blue, packed "
             "from [-1, 1]; grey: no lean)",
             {"debug": "comb"}),
    "shell_count": ("shells drawn per object: blue few .. red the most (`shells`)",
                    {"debug": "shell_count"}),
    "single_shell": ("only the middle shell (of those in shell_range), strands cut through "
                     "opaque", {"debug": "single_shell"}),
    "opacity_shadow": ("the deep opacity maps of the first shadowed light at each shell "
                       "fragment: 1 - transmittance to the end of layers 1, 2 and 4 as red, "
                       "green, blue (black: no fur in front; needs a shadowed light)",
                       {"debug": "opacity_shadow"}),
}


def debug_defines(params: FurParams) -> dict[str, str]:
    return {} if params.debug == "none" else {f"FUR_DEBUG_{params.debug.upper()}": "1"}


def fur_pattern(params: FurParams) -> FurPattern:
    return pattern(params.pattern, thickness_base=params.thickness_base,
                   thickness_tip=params.thickness_tip,
                   length_variation=params.length_variation, seed=params.seed)


def strands_per_tile(params: FurParams) -> int:
    if params.heightfield is not None:
        return IMAGE_TILE_STRANDS
    grid = max(1, round(math.sqrt(fur_pattern(params).strands)))
    return grid * grid


def tiles_per_unit(params: FurParams) -> float:
    """Fur volume tiles per world unit along the surface, from strands per square unit."""
    return math.sqrt(params.density / strands_per_tile(params))


def fur_volume_texture(frame: Frame, params: FurParams,
                       heightfield: Path | None) -> moderngl.TextureArray:
    """The object's fur volume, made once per renderer and pattern."""
    if heightfield is not None:
        softness = params.strand_softness
        return frame.resources.texture(
            ("fur_volume", str(heightfield), softness),
            lambda ctx: volume_texture(ctx, heightfield_volume(load_heightfield(heightfield),
                                                               softness=softness)))
    spec = fur_pattern(params)
    return frame.resources.texture(("fur_volume", spec),
                                   lambda ctx: volume_texture(ctx, strand_volume(spec)))


def object_scale(obj: SceneObject) -> np.ndarray:
    """World length of the object's unit axes (its model matrix's scale)."""
    return np.linalg.norm(obj.model[:3, :3], axis=0)


def fur_scale(obj: SceneObject) -> tuple[float, float, float]:
    """``u_fur_scale``: the object's axes to world units, for the volume lookups."""
    return tuple(float(s) for s in object_scale(obj))


def self_shadowing(params: FurParams) -> bool:
    """Whether the fur shadows itself through deep opacity maps; with ``self_shadow_density``
    0 it does not draw them and gamma(h) darkens it for every light."""
    return params.self_shadow_density > 0.0


def vertex_constants(obj: SceneObject, shell_depth: float | None = None) -> dict[str, Any]:
    """Uniforms of the fur vertex shader fixed for the object (and the shell depth)."""
    constants = {"u_fur_scale": fur_scale(obj)}
    if shell_depth is not None:
        constants["u_shell_depth"] = shell_depth
    return constants


class FurMaterial(Material):
    """What every fur material has (its ``params`` are a :class:`FurParams`): the heightfield
    image checked and resolved, the fur volume and its tiling as inputs, its programs receiving
    the deep opacity maps, and shells and fins reaching ``fur_length`` beyond the mesh (along
    the comb-bent normal: materials/techniques/shells.glsl). Its shadow caster is the fur's
    (``fur_shadow.FurShadow``), given by each fur material with its own vertex stage."""

    params: FurParams
    motion = ReachMotion("fur_length")
    # the cost model's seconds (benchmarks/cost_model.py calibrate): a shell over a triangle
    # and over a covered pixel, and the fins' geometry over a triangle, each a sample
    shell_triangle_seconds: ClassVar[float] = 330e-9
    shell_pixel_seconds: ClassVar[float] = 540e-9
    fin_triangle_seconds: ClassVar[float] = 3.5e-6

    def check_files(self, where: str | None) -> None:
        """Bad input for a heightfield image that is missing, not a file or unreadable
        (before GL work); its errors name the file and the key."""
        if self.params.heightfield is None:
            return
        key = f"{where}.heightfield" if where else "heightfield"
        load_heightfield(self.file_parameter(self.params.heightfield, "heightfield image",
                                             key), key)

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """The mesh, then its shells (each over the triangles and the pixels the fur covers)
        and fins, as many shells as the level of detail gives where the object comes
        nearest (before the mesh loads, the fewest: a lower bound)."""
        p = self.params
        works = [*super().work(obj, job),
                 Work(f"{obj.label}: the fur volume", 1, FUR_VOLUME_SECONDS, obj.key("pattern"),
                      Per.RENDER)]
        if p.shells == 0:
            return works
        low = min(p.min_shells, p.shells)
        shells = float(low) if obj.screen is None else float(np.clip(
            obj.screen.pixels_across(p.fur_length) / p.lod_error, low, p.shells))
        key = obj.key("shells")
        works.append(Work(f"{obj.label}: {shells:.0f} shells x {counted(obj.triangles)} "
                          "triangles", shells * obj.triangles, self.shell_triangle_seconds,
                          key))
        covered = obj.covered_pixels(job, p.fur_length * (obj.screen.scale if obj.screen
                                                          else 1.0))
        if covered is not None:
            works.append(Work(f"{obj.label}: {shells:.0f} shells over {counted(covered)} "
                              "pixels", shells * covered, self.shell_pixel_seconds, key))
        if p.fins:
            works.append(Work(f"{obj.label}: fins over {counted(obj.triangles)} triangles",
                              obj.triangles, self.fin_triangle_seconds, obj.key("fins")))
        return works

    def held_memory(self, obj: SceneObject) -> dict[str, int]:
        path = self.heightfield_path()
        if path is None:
            return {}
        width, height, _ = check_image(path, bytes_per_pixel=HEIGHTFIELD_BYTES_PER_TEXEL)
        return {f"fur volume of {path}": width * height * HEIGHTFIELD_GPU_BYTES_PER_TEXEL}

    def heightfield_path(self) -> Path | None:
        return None if self.params.heightfield is None else \
            self.resolve_path(self.params.heightfield)

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        return {**super().uniforms(frame), "u_fur_tiles": tiles_per_unit(self.params)}

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        return {**super().textures(frame),
                "u_fur_volume": fur_volume_texture(frame, self.params, self.heightfield_path())}

    def defines(self, obj: SceneObject) -> dict[str, str]:
        """The fur's programs receive the deep opacity maps (lighting/shadows.glsl) unless
        ``self_shadow_density`` is 0: where the scene draws them, a shadowed light reaches a
        forward shell through the fur in front."""
        defines = super().defines(obj)
        if self_shadowing(self.params):
            defines["OPACITY_RECEIVER"] = "1"
        return defines


def projected_fur_pixels(frame: Frame, obj: SceneObject, fur_length: float) -> float:
    """How many pixels the fur layer is thick where the object comes nearest the camera."""
    low, high = obj.mesh.bounds()
    scale = float(object_scale(obj).max())
    centre = obj.model @ np.append((low + high) / 2.0, 1.0)
    radius = 0.5 * float(np.linalg.norm(high - low)) * scale
    camera = np.asarray(frame.scene.camera.position, dtype=np.float64)
    distance = max(float(np.linalg.norm(centre[:3] - camera)) - radius,
                   frame.scene.camera.near)
    focal = 0.5 * frame.height * frame.projection[1, 1]  # pixels per unit at distance 1
    return fur_length * scale * focal / distance


def shell_count(frame: Frame, obj: SceneObject, params: FurParams) -> float:
    """The continuous shell count for the object this frame (see the module documentation)."""
    pixels = projected_fur_pixels(frame, obj, params.fur_length)
    return float(np.clip(pixels / params.lod_error, min(params.min_shells, params.shells),
                         params.shells))


def shell_depth(k: int, count: float) -> float:
    """Depth of shell ``k`` of a continuous count: the root shell (0) on the skin, the others at
    the middle of the slabs the rest of the layer is cut into (``count - 1`` of them)."""
    if k == 0:
        return 0.0
    return min((k - 0.5) / max(count - 1.0, 1e-6), 1.0)


def shell_layout(count: float, shell_range: tuple[float, float] = (0.0, 1.0),
                 debug: str = "none") -> list[tuple[float, float] | None]:
    """(depth, fade) of each shell drawn for a continuous count (None: not drawn: outside the
    range, or not shown by the debug view). The outermost fades with the count's fraction."""
    drawn = math.ceil(count - 1e-9)
    low, high = shell_range
    in_range = [k for k in range(drawn) if low <= shell_depth(k, count) <= high]
    if debug in ("comb", "shell_count"):
        shown = {0}  # drawn on the root shell, the skin
    elif debug == "single_shell":
        shown = {in_range[len(in_range) // 2]} if in_range else set()
    else:
        shown = set(in_range)
    return [(shell_depth(k, count), 1.0 if k < drawn - 1 else count - (drawn - 1))
            if k in shown else None for k in range(drawn)]
