"""The light interface, and the deferred pass that draws all lights of one type.

A light type is a class with a unique ``name`` (the scene file's ``type``), a pydantic ``Params``
model, a GLSL file defining ``vec3 <glsl_function>(LightRecord light, Surface s, vec3 P, vec3 V)``
and a ``record(view)`` method packing the light into four vec4s in view space
(``common/lighting.glsl`` documents the layout). The same record feeds both pipelines: the deferred
pass reads it per instance, the forward pass loops over all records per fragment.

``volume`` says how the deferred pass bounds a light: ``"fullscreen"`` (directional, ambient) or
``"sphere"`` (the record's ``position.xyz`` is the centre and ``position.w`` the radius), so that
cost follows the pixels a light touches.
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import Field

from deferred.core.passes import FullscreenPass, Order, Phase, RenderPass
from deferred.gbuffer.layout import DEPTH, GBUFFER_COLOR_TARGETS
from deferred.gl.context import GL_DEPTH_CLAMP
from deferred.gl.target_spec import TargetSpec
from deferred.gl.targets import LIGHT_ACCUMULATION
from deferred.params import Params, validate_params
from deferred.scene.meshes import MeshData, build_mesh
from deferred.validation import Radiance

if TYPE_CHECKING:
    from deferred.core.frame import Frame

Vec3 = tuple[float, float, float]
DISPATCH_FILE = "generated/lights.glsl"
LISTED_DISPATCH_FILE = "generated/listed_lights.glsl"  # after lights/light_lists.glsl only
SHADING_DISPATCH_FILE = "generated/shading_models.glsl"
RANGE_UNIFORM_PREFIX = "u_light_range_"
# Full-screen lights a frame may have: their records are also a uniform array
# (``u_fullscreen_lights``, four vec4s each), which every pixel reads in the list and forward
# paths: llvmpipe reads a uniform faster than a texel. lights.toml, 1 light, interleaved in one
# process: the tiled shading 13.0 -> 11.7 ms at 640x360 and 45-47 -> 40-42 ms at 1280x720;
# the Forward+ frame at 16 lights 30.8-31.0 -> 27.7-28.5 ms at 640x360.
FULLSCREEN_LIGHT_CAPACITY = 16
FULLSCREEN_UNIFORM = "u_fullscreen_lights"
FULLSCREEN_LIGHTS_FILE = "common/fullscreen_lights.glsl"


class LightParams(Params):
    color: Radiance = Field((1.0, 1.0, 1.0), description="linear RGB colour, each >= 0")
    intensity: float = Field(1.0, ge=0.0, description="multiplier of color")


class Light:
    name: ClassVar[str]
    Params: ClassVar[type[LightParams]] = LightParams
    glsl_file: ClassVar[str] = ""
    glsl_function: ClassVar[str] = ""
    volume: ClassVar[Literal["fullscreen", "sphere"]] = "fullscreen"
    shader_root: ClassVar[Traversable | Path | None] = None
    type_id: ClassVar[int] = 0  # set by the registry

    def __init__(self, params: LightParams | None = None):
        self.params = params if params is not None else self.Params()

    @classmethod
    def from_dict(cls, values: dict[str, Any], where: str | None = None) -> Light:
        return cls(validate_params(cls.Params, values, where))

    def radiance(self) -> np.ndarray:
        return np.asarray(self.params.color, dtype=np.float64) * self.params.intensity

    def record(self, view: np.ndarray) -> np.ndarray:
        """(4, 4) float32: color, position, direction, extra (view space). See lighting.glsl.
        A function of ``params`` and ``view`` alone: the light buffer packs the records again
        only when one of them changes (``LightBuffer.upload``)."""
        raise NotImplementedError

    @classmethod
    def records(cls, lights: list[Light], view: np.ndarray) -> np.ndarray:
        """``(len(lights), 4, 4)`` float32: :meth:`record` of each light of this type. A type
        with many lights a frame (point, spot) overrides it with numpy over all of them: one
        ``record`` call per light cost 25 ms a frame at 1024 lights."""
        return np.stack([np.asarray(light.record(view), dtype=np.float32).reshape(4, 4)
                         for light in lights]) if lights else np.zeros((0, 4, 4), np.float32)


def view_point(view: np.ndarray, point) -> np.ndarray:
    return (view @ np.append(np.asarray(point, dtype=np.float64), 1.0))[:3]


def view_points(view: np.ndarray, points: np.ndarray) -> np.ndarray:
    """:func:`view_point` of ``(n, 3)`` points."""
    return points @ view[:3, :3].T + view[:3, 3]


def view_directions(view: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """:func:`view_direction` of ``(n, 3)`` directions."""
    d = directions @ view[:3, :3].T
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)


def radiances(lights: list[Light]) -> np.ndarray:
    """:meth:`Light.radiance` of each light, ``(n, 3)``."""
    return np.array([light.params.color for light in lights], np.float64) * \
        np.array([light.params.intensity for light in lights], np.float64)[:, None]


def view_direction(view: np.ndarray, direction) -> np.ndarray:
    d = view[:3, :3] @ np.asarray(direction, dtype=np.float64)
    return d / max(np.linalg.norm(d), 1e-12)


def light_range_uniform(light_type: type[Light]) -> str:
    """The ``ivec2`` uniform holding (first record, count) of one light type this frame: named
    by type id, since a plugin's type name need not be a GLSL identifier."""
    return f"{RANGE_UNIFORM_PREFIX}{light_type.type_id}"


def light_dispatch_glsl(light_types: list[type[Light]]) -> str:
    """GLSL of the light dispatch (and the shading models' dispatch, which the lights call):

    - ``evaluate_light``: one light of any type, a switch on its type id;
    - ``evaluate_volume_light``: the same over the volume types only (the lists' lights);
    - ``evaluate_fullscreen_lights``, ``evaluate_volume_lights``: every full-screen (or volume)
      light, one loop per type over its range of the light buffer (sorted by type,
      :class:`~deferred.lighting.buffer.LightBuffer`), each calling its function directly, with
      no test of the type per light. The full-screen lights
      come first in the buffer, and their loops read the same records from the uniform array
      ``u_fullscreen_lights`` (``fullscreen_light``).
    """
    lines = [f'#include "{SHADING_DISPATCH_FILE}"',
             f"#define FULLSCREEN_LIGHT_CAPACITY {FULLSCREEN_LIGHT_CAPACITY}",
             f'#include "{FULLSCREEN_LIGHTS_FILE}"']
    lines += [f'#include "{cls.glsl_file}"' for cls in light_types]
    lines += [f"uniform ivec2 {light_range_uniform(cls)};" for cls in light_types]

    def switch(name: str, types: list[type[Light]]) -> list[str]:
        body = [f"vec3 {name}(LightRecord light, Surface s, vec3 P, vec3 V) {{",
                "    int kind = int(light.color.w + 0.5);"]
        body += [f"    if (kind == {cls.type_id}) return {cls.glsl_function}(light, s, P, V);"
                 for cls in types]
        return [*body, "    return vec3(0.0);", "}"]

    def loops(name: str, types: list[type[Light]], fetch: str) -> list[str]:
        # do-while: the test at the end of the body. Where a shader runs as SIMD lanes with
        # masks (llvmpipe), a for loop runs its body once more than it has lights, all lanes
        # masked, to find that every lane is done. The `if` keeps a type with no lights from
        # adding one (on llvmpipe by masking the body, which still runs; elsewhere by
        # skipping it).
        body = [f"vec3 {name}(Surface s, vec3 P, vec3 V) {{", "    vec3 total = vec3(0.0);"]
        for cls in types:
            r = light_range_uniform(cls)
            body += [f"    if ({r}.y > 0) {{",
                     f"        int k = {r}.x;",
                     "        do {",
                     f"            total += {cls.glsl_function}({fetch}(k), s, P, V);",
                     f"        }} while (++k < {r}.x + {r}.y);",
                     "    }"]
        return [*body, "    return total;", "}"]

    fullscreen = [cls for cls in light_types if cls.volume == "fullscreen"]
    volumes = [cls for cls in light_types if cls.volume != "fullscreen"]
    lines += switch("evaluate_light", light_types)
    lines += switch("evaluate_volume_light", volumes)
    lines += loops("evaluate_fullscreen_lights", fullscreen, "fullscreen_light")
    lines += loops("evaluate_volume_lights", volumes, "fetch_light")
    return "\n".join(lines) + "\n"


def listed_dispatch_glsl(light_types: list[type[Light]]) -> str:
    """GLSL of ``evaluate_listed_slots(first, length, s, P, V)``: the volume lights of one light
    list (``lights/listed_lights.glsl``), a do-while loop per volume type in type order.

    A list holds its lights in light order (the culling's), and the light buffer its types in
    type order (:class:`~deferred.lighting.buffer.LightBuffer`), so each type's entries follow one
    another: each loop runs over its type's and calls its function, where a switch on the type
    per entry ran every type's evaluation for every entry on llvmpipe (an `if` skips nothing
    there; lights.toml at 640x360, half the lights spots: the tiled shading 35.9 -> 50.8 ms at
    1024 lights). A loop but the last stops at the first entry past its type's range, whose
    evaluation runs masked once on llvmpipe."""
    volumes = sorted((cls for cls in light_types if cls.volume != "fullscreen"),
                     key=lambda cls: cls.type_id)
    lines = ["vec3 evaluate_listed_slots(int first, int length, Surface s, vec3 P, vec3 V) {",
             "    vec3 total = vec3(0.0);",
             "    int k = 0;"]
    for position, cls in enumerate(volumes):
        r = light_range_uniform(cls)
        last = position == len(volumes) - 1
        lines += [f"    if (k < length) {{  // {cls.name} lights",
                  *([] if last else [f"        int end = {r}.x + {r}.y;"]),
                  "        do {",
                  "            ListedLight listed = listed_light(first + k);",
                  *([] if last else ["            if (listed.index >= end) break;"]),
                  "            if (listed_light_reaches(listed, P))",
                  f"                total += {cls.glsl_function}(listed_light_record(listed), "
                  "s, P, V);",
                  "        } while (++k < length);",
                  "    }"]
    return "\n".join([*lines, "    return total;", "}"]) + "\n"


@lru_cache(maxsize=1)
def light_volume_mesh() -> tuple[MeshData, float]:
    """An icosphere and the scale that makes it enclose the unit sphere (faces sit inside it)."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    faces = np.asarray(sphere.faces)
    vertices = np.asarray(sphere.vertices)
    normals = np.asarray(sphere.face_normals)
    inscribed = np.min(np.abs(np.sum(normals * vertices[faces[:, 0]], axis=1)))
    mesh = build_mesh("light-volume", vertices, faces, vertices,
                      uvs=np.zeros((len(vertices), 2)))
    return mesh, 1.0 / float(inscribed)


def surface_pass(name: str, fragment: str, inputs: dict[str, str],
                 creates: dict[str, TargetSpec], background: tuple[float, float, float],
                 defines: dict[str, str] | None = None) -> FullscreenPass:
    """A full-screen pass of the lighting phase that runs on the scene's surfaces only: it
    creates ``creates`` cleared to ``background`` (alpha 0; its shader's ``u_background``, for
    pixels with depth but no surface), and draws its triangle on the far plane with the depth
    test "greater" against the G-buffer's depth (``common/fullscreen_triangle.glsl``). On
    llvmpipe a block of pixels failing that test is skipped, where an ``if`` in the shader
    skips nothing: the list shading (``deferred.lighting.lists.list_shading_pass``) and the
    volumes path's background pass."""
    cleared = (*background, 0.0)
    return FullscreenPass(name, Phase.LIGHTING, fragment, inputs, tuple(creates),
                          defines={"FULLSCREEN_AT_FAR": "1", **(defines or {})},
                          creates={target: replace(spec, clear=cleared)
                                   for target, spec in creates.items()},
                          uniforms=lambda frame: {"u_background": background},
                          depth=DEPTH, depth_test=True, depth_func="greater",
                          order=Order.FIRST)


class LightTypePass(RenderPass):
    """Deferred lighting of every light of one type, instanced, added into light accumulation.

    It reads the G-buffer, including the scene's declared data (``gbuffer``, the colour targets
    of the scene's layout), so every shading model finds what it reads."""

    phase = Phase.LIGHTING
    writes = (LIGHT_ACCUMULATION,)

    def __init__(self, light_type: type[Light], occlusion: str | None = None,
                 gbuffer: tuple[str, ...] = GBUFFER_COLOR_TARGETS):
        self.light_type = light_type
        self.name = f"lighting.{light_type.name}"
        self.occlusion = occlusion  # target holding ambient occlusion (SSAO), if any
        self.gbuffer = gbuffer
        self.samples = (*gbuffer, *((occlusion,) if occlusion else ()))
        self.reads = (*self.samples, DEPTH, LIGHT_ACCUMULATION)

    def execute(self, frame: Frame) -> None:
        offset, count = frame.light_buffer.range(self.light_type)
        if count == 0:
            return
        sphere = self.light_type.volume == "sphere"
        vertex = "lights/volume.vert" if sphere else "lights/fullscreen.vert"
        defines = {"LIGHT_FUNCTION": self.light_type.glsl_function}
        if self.occlusion:
            defines["HAS_SSAO"] = "1"
        if not sphere:
            defines["FULLSCREEN_AT_FAR"] = "1"
        program = frame.shaders.program(vertex, "lights/accumulate.frag", defines=defines)
        frame.use_framebuffer((LIGHT_ACCUMULATION,), DEPTH, depth_write=False)
        textures = frame.target_samplers(self.gbuffer)
        if self.occlusion:
            textures["u_ssao"] = frame.target(self.occlusion)
        uniforms = {"u_light_offset": offset}
        if sphere:
            # Back faces of the bounding sphere, kept where the surface lies in front of them:
            # works with the camera inside the volume; depth clamp stops the far plane cutting it.
            mesh, scale = light_volume_mesh()
            frame.set_state(depth_test=True, depth_func="gequal", cull="front", blend="add")
            frame.bind(program, {**uniforms, "u_volume_scale": scale}, textures)
            frame.ctx.enable_direct(GL_DEPTH_CLAMP)
            try:
                frame.draw_mesh(mesh, program, instances=count)
            finally:
                frame.ctx.disable_direct(GL_DEPTH_CLAMP)
        else:
            # On the far plane, drawn where the depth is nearer: the background's pixels are
            # skipped, which an `if` in the shader cannot do on llvmpipe (light_lists.py).
            frame.set_state(depth_test=True, depth_func="greater", blend="add")
            frame.bind(program, uniforms, textures)
            frame.draw_fullscreen(program, instances=count)


