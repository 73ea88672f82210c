"""Curling and clumping shell fur (P. Silva, Y. Bando, B.-Y. Chen, T. Nishita, "Curling and
Clumping Fur Represented by Texture Layers").

The fur is N texture layers over the mesh (section 4; the shared fur technique's volume, level
of detail and fins, ``techniques/fur.py``), layer n at normalized length h = (1 + n)/N over an
opaque skin, each displaced in the vertex shader by the strand's bend and curl (Eq. 1, 4) and
clumped in the fragment shader (Eq. 5, Algorithm 2); lit with Kajiya-Kay and the shadow factor
gamma (Eq. 6). Per object and over time (``state.py``, the material's simulation): the wetness
mask (3.1, Algorithm 1; ``techniques/wetness.py``), built from random droplets or an image and
drying at ``dry_rate``, and one mass-spring strand per triangle (3.2.1, Eq. 2, 3;
``techniques/strands.py``) under gravity and gusting wind.

The package: ``params.py`` (the parameters and the simulation's limits), ``state.py`` (the
state over time), ``color.py`` (generated colour textures), ``passes.py`` (the layers and
fins, and the state as the passes' input), this module (the material).

Pipelines:
- deferred: the base mesh goes to the G-buffer with the ``kajiya_kay`` shading model and the
  strand's chord as its ``strand_tangent``; the lights shade it; the layers are material-phase
  passes taking their light from the light accumulation at the root under them (as Revie's
  shells do), so their cost does not grow with the number of lights;
- forward: every layer fragment is lit by every light with its own strand tangent.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import moderngl

from deferred.api import (
    InputError,
    SurfacePasses,
    check_image,
    image_texture_bytes,
    materials,
    read_image,
)

from ..techniques.fur import (
    FUR_DEBUG_VIEWS,
    FUR_UNIFORM_OVERRIDES,
    FurMaterial,
    debug_defines,
    vertex_constants,
)
from ..techniques.fur_shadow import FurShadow
from ..techniques.wetness import read_mask_image
from .color import pattern_texture
from .params import NOT_UNIFORMS, ShellFurParams, layers_uniform
from .passes import CHORD, FUR_VERTEX, STATE, FurLayers
from .state import SIMULATION, StrandMotion

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject


@materials.register
class ShellFurMaterial(FurMaterial):
    name = "shell_fur"
    Params = ShellFurParams
    surface_shader = "materials/shell_fur/surface.glsl"
    inputs_from_params = True  # uniforms from the params, textures from frame.resources
    shading_model = "kajiya_kay"
    uniform_overrides = {**FUR_UNIFORM_OVERRIDES, **{key: None for key in NOT_UNIFORMS},
                         "shells": layers_uniform}
    # the simulation's set-up (ShellFurState), and the passes built once
    # the cost model's seconds (benchmarks/cost_model.py calibrate)
    shell_triangle_seconds = 360e-9
    shell_pixel_seconds = 510e-9
    fin_triangle_seconds = 1.6e-6
    timeline_growing = ("droplets",)  # fallen droplets stay (Algorithm 1 blends, never removes)
    timeline_fixed = ("fur_length", "mask_size", "wetness_mask", "time_step", "settle", "seed",
                      "fins", "shading", "strand_variation", "curl_variation")
    debug_views = {
        **{name: view for name, view in FUR_DEBUG_VIEWS.items() if name not in ("comb",
                                                                                 "samples")},
        "samples": ("the light sample each layer and fin fragment used: green its root's "
                    "pixel (or a neighbour), yellow its own pixel, red none; white in the "
                    "forward pipeline, which lights every fragment", {"debug": "samples"}),
        "wetness": ("the wetness mask on the skin: a colour per clump, as bright as it is "
                    "wet; black dry (Silva et al. Fig. 11's inset)", {"debug": "wetness"}),
    }

    # the base mesh into the G-buffer (kajiya_kay along the strand's chord) and its forward
    # twin, then the fins and layers; every pass, and the shadows, read the object's state
    techniques = (SurfacePasses(vertex=FUR_VERTEX, inputs=(STATE,), extra_defines=CHORD,
                                constants=lambda obj: vertex_constants(obj, 0.0)),
                  FurLayers(fur_light="shell_fur_light", material="shell_fur"))
    shadow = FurShadow(FUR_VERTEX, inputs=(STATE,))
    simulation = SIMULATION
    motion = StrandMotion("fur_length")  # the tips' own motion too (wind)

    def __init__(self, params: ShellFurParams | None = None, base_dir: Path | None = None):
        super().__init__(params, base_dir)
        self.shading_model = self.params.shading

    def check_files(self, where: str | None) -> None:
        super().check_files(where)
        for key in ("color_texture", "wetness_mask"):
            value = getattr(self.params, key)
            if value is None:
                continue
            name = f"{where}.{key}" if where else key
            path = self.file_parameter(value, key.replace("_", " ") + " image", name)
            try:
                read_mask_image(path) if key == "wetness_mask" else read_image(path)
            except InputError as exc:
                raise InputError(exc.message, name) from None

    def held_memory(self, obj: SceneObject) -> dict[str, int]:
        """The fur volume and the colour texture (the wetness mask is the simulation's)."""
        held = super().held_memory(obj)
        if self.params.color_texture is not None:
            path = self.resolve_path(self.params.color_texture)
            width, height, _ = check_image(path)
            held[f"texture {path}"] = image_texture_bytes(width, height)
        return held

    def wetness_mask_path(self, params: ShellFurParams | None = None) -> Path | None:
        params = params or self.params
        return None if params.wetness_mask is None else self.resolve_path(params.wetness_mask)

    def defines(self, obj: SceneObject) -> dict[str, str]:
        # The layers reject light samples the G-buffer shows occluded (Revie's Figure 2.8 fix)
        # by the depths of the fur_light gather (materials/techniques/fur_light.glsl), always.
        defines = {**super().defines(obj), **debug_defines(self.params)}
        if self.params.fur_mapping == "uv":
            defines["FUR_UV_MAPPING"] = "1"
        if self.has_color_map():
            defines["FUR_COLOR_MAP"] = "1"
        if self.params.shading == "marschner":
            defines["FUR_MARSCHNER"] = "1"
        return defines

    def has_color_map(self) -> bool:
        """Whether the colour varies over the UVs (a texture or a pattern), else the tint."""
        return self.params.color_texture is not None or self.params.color_pattern != "none"

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        params = self.params
        textures = super().textures(frame)
        if params.color_texture is not None:
            textures["u_color_map"] = frame.resources.image_texture(
                self.resolve_path(params.color_texture))
        elif self.has_color_map():
            textures["u_color_map"] = frame.resources.texture(
                ("shell_fur_pattern", params.color_pattern, params.seed, params.color,
                 params.pattern_color), lambda ctx: pattern_texture(ctx, params))
        return textures
