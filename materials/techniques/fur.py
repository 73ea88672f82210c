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
  (``self_shadow_density``; :meth:`FurMaterial.draw_opacity`, ``lighting/shadows.glsl``).
- **Level of detail**: the shell count follows the fur layer's projected thickness,
  ``n = clamp(pixels / lod_error, min_shells, shells)``, continuous; the depths move with it and
  the outermost fades by the fraction, so a dolly never pops (:func:`shell_count`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import moderngl
import numpy as np
from pydantic import Field, model_validator

from deferred.api import (
    SHADOW_CASTER_DEFINES,
    Material,
    MaterialParams,
    ShadowView,
    check_image,
)

from .fur_volume import VOLUME_LAYERS, FurPattern, pattern, strand_volume, volume_texture
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
SHADOW_CASTER_FRAGMENT = "materials/techniques/fur_caster.frag"
SHADOW_SHELLS = 8  # most shells a fur object casts its shadow with (with its root shell)
OPACITY_FRAGMENT = "materials/techniques/fur_opacity.frag"
OPACITY_SHELLS = 12  # most shells the fur draws into the deep opacity maps (without the skin)
OPACITY_ENVELOPE = 1.0  # the shell depth of the fur's front in the opacity maps: the tips


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


class FurMaterial(Material):
    """What every fur material has (its ``params`` are a :class:`FurParams`): the heightfield
    image checked and resolved, the fur volume and its tiling as inputs, and the constants of
    the fur vertex shader for an object."""

    params: FurParams

    def check_files(self, where: str | None) -> None:
        """Bad input for a heightfield image that is missing, not a file or unreadable
        (before GL work); its errors name the file and the key."""
        if self.params.heightfield is None:
            return
        key = f"{where}.heightfield" if where else "heightfield"
        load_heightfield(self.file_parameter(self.params.heightfield, "heightfield image",
                                             key), key)

    def motion_extent(self, obj: SceneObject) -> float:
        """The shells and fins reach fur_length beyond the mesh (along the comb-bent normal:
        materials/techniques/shells.glsl)."""
        return float(self.params.fur_length)

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
        if self.opacity_shadows:
            defines["OPACITY_RECEIVER"] = "1"
        return defines

    # -- shadows -------------------------------------------------------------------------------
    @property
    def opacity_shadows(self) -> bool:  # type: ignore[override]
        """The fur shadows itself through deep opacity maps; with ``self_shadow_density`` 0
        it does not draw them and gamma(h) darkens it for every light."""
        return self.params.self_shadow_density > 0.0
    fur_vertex: str = ""  # the material's fur vertex shader (its shells' and its caster's)

    def shadow_textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        """The per-object textures the fur vertex shader reads (a comb field, a simulation's
        state), for the shadow caster."""
        return {}

    def draw_shadow(self, frame: Frame, obj: SceneObject, view: ShadowView) -> None:
        """The fur's depth from a light, through the material's own fur vertex shader seen from
        it (:data:`SHADOW_CASTER_DEFINES`), which pushes it a strand's length away from the
        light (so its own skin, lit through the fur in front, does not shadow itself at the
        roots).

        Where the light has deep opacity maps (``view.opacity_maps``) and the fur is in them
        (``self_shadow_density`` above 0), only the root shell (the skin, opaque) casts depth:
        the body shadows its own far side and what lies behind it, and the fur's translucent
        shadow, on other surfaces as on itself, is the maps' alone (``lighting/shadows.glsl``:
        a surface beyond the fur's back keeps exp(-k x the fur's optical depth) there, the
        fur's own shells and skin the transmittance at their depth). Dithered shells in the
        depth map too would shadow the fur twice: toward the terminator a shell at height h
        reaches a flat skin under it where the light meets the skin at more than arccos(h)
        from its normal, however far it is pushed, and the deferred shells read their light
        from the skin's pixels.

        Otherwise (``self_shadow_density`` 0, or a pipeline that draws no maps) the root shell
        and up to ``SHADOW_SHELLS`` shells above it cast, each kept by a dither under its
        opacity (``materials/techniques/fur_caster.frag``), so the floor darkens with the fur's
        density; gamma(h) is the fur's own self-shadowing then."""
        params = self.params
        if params.shells == 0 or not self.fur_vertex:
            super().draw_shadow(frame, obj, view)
            return
        program = frame.shaders.program(self.fur_vertex, SHADOW_CASTER_FRAGMENT,
                                        defines={**self.defines(obj), **SHADOW_CASTER_DEFINES})
        count = min(params.shells, SHADOW_SHELLS) + 1.0  # the root shell and the slabs above
        drawn = 1 if view.opacity_maps and self.opacity_shadows else int(count)
        # the light's matrices offered, not set: the shader declares them under the camera's
        # names (renamed by the defines), which is what strict mode reads
        frame.bind(program, {**self.vertex_constants(obj), "u_shell_depth": 0.0,
                             "u_root_shell": True,
                             "u_shell_weight": VOLUME_LAYERS / (count - 1.0)},
                   self.shadow_textures(frame, obj),
                   offered={**frame.object_uniforms(obj), **view.camera_uniforms},
                   material=frame.material_inputs(self))
        for k in range(drawn):
            if k:
                frame.set_uniforms(program, {"u_shell_depth": shell_depth(k, count),
                                             "u_root_shell": False})
            frame.draw_mesh(obj.mesh, program)

    def opacity_layer(self, obj: SceneObject) -> float:
        """The fur's world thickness: a strand's length."""
        return float(self.params.fur_length * object_scale(obj).max())

    def opacity_shells(self, frame: Frame, obj: SceneObject) -> int:
        """How many outer shells the fur draws into the deep opacity maps this frame: as many
        as it draws in view (:func:`shell_count`, rounded up; the root shell is the skin's,
        the depth atlas's), at most ``OPACITY_SHELLS``. Far away the fur's self-shadowing
        takes few pixels and few shells; each shell then stands for more of the volume, so the
        optical depth summed through the fur stays the same."""
        params = self.params
        wanted = math.ceil(shell_count(frame, obj, params) - 1e-9)
        return max(1, min(wanted, params.shells, OPACITY_SHELLS))

    def draw_opacity(self, frame: Frame, obj: SceneObject, view: ShadowView,
                     stage: str) -> None:
        """The fur in the deep opacity maps, where it is (not pushed away as the depth casters
        are). Stage "first": the fur's envelope, the shell through its strands' tips, which every
        shell drawn in view lies inside, so the front is where the fur begins along each texel
        (an inner shell would leave the tips beyond it out of the maps, with no fur in front).
        Stage "density": :meth:`opacity_shells` outer shells, each adding the optical depth of
        the opacity it draws (``materials/techniques/fur_opacity.frag``)."""
        params = self.params
        if params.shells == 0 or not self.fur_vertex:
            return
        defines = {**self.defines(obj), **SHADOW_CASTER_DEFINES, "OPACITY_CASTER": "1"}
        if stage == "first":
            defines["OPACITY_FIRST"] = "1"
        program = frame.shaders.program(self.fur_vertex, OPACITY_FRAGMENT, defines=defines)
        count = self.opacity_shells(frame, obj) + 1.0  # as the shells: a root and slabs
        depths = [OPACITY_ENVELOPE] if stage == "first" else \
            [shell_depth(k, count) for k in range(1, int(count))]
        frame.bind(program, {**self.vertex_constants(obj, depths[0]),
                             "u_shell_weight": VOLUME_LAYERS / (count - 1.0)},
                   self.shadow_textures(frame, obj),
                   offered={**frame.object_uniforms(obj), **view.camera_uniforms},
                   material=frame.material_inputs(self))
        for k, depth in enumerate(depths):
            if k:
                frame.set_uniforms(program, {"u_shell_depth": depth})
            frame.draw_mesh(obj.mesh, program)

    @staticmethod
    def vertex_constants(obj: SceneObject, shell_depth: float | None = None) -> dict[str, Any]:
        """Uniforms of the fur vertex shader fixed for the object (and the shell depth)."""
        constants = {"u_fur_scale": fur_scale(obj)}
        if shell_depth is not None:
            constants["u_shell_depth"] = shell_depth
        return constants


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
