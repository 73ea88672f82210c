"""The G-buffer: the one interface between light-receiving materials and lights (Revie 2.1).

| target             | format  | channels                                                |
|--------------------|---------|---------------------------------------------------------|
| albedo_specular    | RGBA8   | albedo.rgb (linear), specular intensity [0, 1]          |
| normal_exponent_id | RGBA16F | view normal (octahedral, 2 ch.), specular exponent,     |
|                    |         | surface id: shading model * 64 + material (0 = none)    |
| linear_depth       | R32F    | linear view depth -z_view (0 = background)              |
| depth              | DEPTH24 | hardware depth (light volumes depth-test against it)    |

4 + 8 + 4 + 4 = 20 bytes per pixel (Killzone 2's budget). View-space position is never stored: it
is reconstructed from the linear depth and the pixel's view ray (``gbuffer/layout.glsl``).

Normals are octahedral-encoded [Cigolle et al. 2014] so a view-space unit vector fits two half
floats. The id channel packs the registry ``type_id`` of the material that wrote the pixel and of
its shading model (:func:`deferred.gbuffer.surface_id.surface_id`), exact in a half float.

Materials may add targets of their own (:class:`deferred.gbuffer.GBufferData`); the GLSL that
declares, writes and fetches them is generated per scene (:func:`data_struct_glsl`,
:func:`data_write_glsl`, :func:`data_fetch_glsl`).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from deferred.gbuffer.surface_id import split_surface_id
from deferred.gl.target_spec import TargetSpec

ALBEDO_SPECULAR = "albedo_specular"
NORMAL_EXPONENT_ID = "normal_exponent_id"
LINEAR_DEPTH = "linear_depth"
DEPTH = "depth"
# Per-pixel motion (temporal effects: deferred.effects.taa): where each pixel's surface was in the
# last frame, in pixels, as this frame's position minus the last frame's, without the jitter.
MOTION = "motion"
MOTION_SPEC = TargetSpec(2, "f2", "motion in pixels: this frame's position - the last frame's "
                                  "(unjittered)", clear=(0.0, 0.0))

GBUFFER_COLOR_TARGETS = (ALBEDO_SPECULAR, NORMAL_EXPONENT_ID, LINEAR_DEPTH)

GBUFFER_TARGETS: dict[str, TargetSpec] = {
    ALBEDO_SPECULAR: TargetSpec(4, "f1", "albedo.rgb, specular intensity", clear=(0.0,) * 4),
    NORMAL_EXPONENT_ID: TargetSpec(4, "f2", "octahedral view normal (2), specular exponent, "
                                            "surface id (shading model, material)",
                                   clear=(0.0,) * 4),
    LINEAR_DEPTH: TargetSpec(1, "f4", "linear view depth (0 = background)", clear=(0.0,)),
    DEPTH: TargetSpec(1, "f4", "hardware depth", depth=True, clear=(1.0,)),
}


_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


@dataclass(frozen=True)
class GBufferData:
    """Per-pixel data beyond the core G-buffer: a target ``name`` of ``format`` (R8 ... RGBA32F)
    whose channels are called ``channels`` in ``gbuffer.exr`` (as ``name.channel``)."""

    name: str
    format: str
    channels: tuple[str, ...]
    description: str = ""

    def __post_init__(self) -> None:
        if not _NAME.match(self.name) or self.name in GBUFFER_TARGETS:
            raise ValueError(f"G-buffer data name '{self.name}' must be lower_snake_case and not "
                             f"a core target ({', '.join(GBUFFER_TARGETS)})")
        spec = self.spec  # validates the format
        if len(self.channels) != spec.components:
            raise ValueError(f"G-buffer data '{self.name}': {self.format} has "
                             f"{spec.components} channels, {len(self.channels)} names given")

    @property
    def spec(self) -> TargetSpec:
        return TargetSpec.from_format(self.format, self.description or self.name)


@dataclass
class GBufferLayout:
    """The G-buffer of one scene: the core targets plus the data its materials declare."""

    data: dict[str, GBufferData]

    @property
    def targets(self) -> dict[str, TargetSpec]:
        return {**GBUFFER_TARGETS, **{name: d.spec for name, d in self.data.items()}}

    @property
    def color_targets(self) -> tuple[str, ...]:
        return (*GBUFFER_COLOR_TARGETS, *self.data)

    @property
    def bytes_per_pixel(self) -> int:
        return sum(spec.bytes_per_pixel for spec in self.targets.values())

    def describe(self) -> dict[str, dict[str, object]]:
        """Target -> format, bytes per pixel, what it holds (``deferred info``, bench, dump)."""
        out = {}
        for name, spec in self.targets.items():
            entry = {"format": spec.format_name, "bytes_per_pixel": spec.bytes_per_pixel,
                     "description": spec.description}
            if name in self.data:
                entry["channels"] = [f"{name}.{c}" for c in self.data[name].channels]
            out[name] = entry
        return out


def surfaces_need_depth(render_pass) -> str | None:
    """The G-buffer's rule for the pass graph (:func:`deferred.core.graph.compile_graph`): a
    pass writing surfaces (the surface id's target) writes or tests the depth too. The
    deferred lighting runs where the depth is nearer than the far plane
    (:func:`deferred.lighting.volumes.surface_pass`), so a surface without it would go unlit;
    one that tests against the depth without writing it draws over surfaces already there."""
    if NORMAL_EXPONENT_ID in render_pass.writes and DEPTH not in render_pass.writes \
            and DEPTH not in render_pass.reads:
        return (f"writes G-buffer surfaces ('{NORMAL_EXPONENT_ID}') with no '{DEPTH}': the "
                "lighting runs only where a surface's depth was written")
    return None


DATA_STRUCT_FILE = "generated/gbuffer_data.glsl"
DATA_FETCH_FILE = "generated/gbuffer_data_fetch.glsl"


def data_write_file(names: Sequence[str]) -> str:
    """The generated GLSL writing these data targets (a material's G-buffer passes)."""
    return f"generated/gbuffer_write/{'+'.join(names) or 'none'}.glsl"


def data_struct_glsl(names: Sequence[str]) -> str:
    """``struct SurfaceData``: one vec4 per declared datum of the scene."""
    fields = [f"    vec4 {name};" for name in names] or ["    float unused;"]
    return "struct SurfaceData {\n" + "\n".join(fields) + "\n};\n"


def data_write_glsl(names: Sequence[str]) -> str:
    """Outputs after the core ones and ``gbuffer_write_data`` for one material's data."""
    first = len(GBUFFER_COLOR_TARGETS)
    lines = [f"layout(location = {first + k}) out vec4 out_{name};"
             for k, name in enumerate(names)]
    lines.append("void gbuffer_write_data(SurfaceData d) {")
    lines += [f"    out_{name} = d.{name};" for name in names]
    lines.append("}")
    return "\n".join(lines) + "\n"


def data_fetch_glsl(names: Sequence[str]) -> str:
    """Samplers ``u_<name>`` and ``gbuffer_fetch_data``: the lights' read of the data."""
    lines = [f"uniform sampler2D u_{name};" for name in names]
    lines.append("SurfaceData gbuffer_fetch_data(ivec2 pixel) {")
    lines.append("    SurfaceData d;")
    lines += [f"    d.{name} = texelFetch(u_{name}, pixel, 0);" for name in names]
    if not names:
        lines.append("    d.unused = 0.0;")
    lines += ["    return d;", "}"]
    return "\n".join(lines) + "\n"


def octahedral_encode(n: np.ndarray) -> np.ndarray:
    """numpy twin of ``octahedral_encode`` in ``gbuffer/layout.glsl``."""
    n = np.asarray(n, dtype=np.float64)
    n = n / np.sum(np.abs(n), axis=-1, keepdims=True)
    xy = n[..., :2].copy()
    neg = n[..., 2] < 0.0
    sign = np.where(xy >= 0.0, 1.0, -1.0)
    folded = (1.0 - np.abs(xy[..., ::-1])) * sign
    xy[neg] = folded[neg]
    return xy


def octahedral_decode(e: np.ndarray) -> np.ndarray:
    """numpy twin of ``octahedral_decode`` in ``gbuffer/layout.glsl``."""
    e = np.asarray(e, dtype=np.float64)
    z = 1.0 - np.abs(e[..., 0]) - np.abs(e[..., 1])
    xy = e.copy()
    neg = z < 0.0
    sign = np.where(e >= 0.0, 1.0, -1.0)
    folded = (1.0 - np.abs(e[..., ::-1])) * sign
    xy[neg] = folded[neg]
    n = np.concatenate([xy, z[..., None]], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def decode(albedo_specular: np.ndarray, normal_exponent_id: np.ndarray,
           linear_depth: np.ndarray) -> dict[str, np.ndarray]:
    """Decode read-back G-buffer targets to named arrays (albedo, normal, depth, ...)."""
    ids = np.rint(normal_exponent_id[..., 3])
    material_id, shading_model = split_surface_id(ids)
    return {
        "albedo": albedo_specular[..., :3],
        "specular_intensity": albedo_specular[..., 3],
        "normal": octahedral_decode(normal_exponent_id[..., :2]).astype(np.float32),
        "specular_exponent": normal_exponent_id[..., 2],
        "surface_id": ids.astype(np.float32),
        "material_id": material_id.astype(np.float32),
        "shading_model": shading_model.astype(np.float32),
        "linear_depth": linear_depth[..., 0],
    }
