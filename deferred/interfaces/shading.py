"""Shading models and the per-pixel data materials declare (Unreal's shading-model id and custom
data, Filament's shading models).

A **shading model** is a BRDF in one GLSL file, defining
``vec3 <glsl_function>(Surface s, vec3 L, vec3 V, vec3 radiance)``: the light reflected toward
``V`` (unit, to the viewer) by a surface lit from ``L`` (unit, to the light) with ``radiance``.
Both pipelines call it: the deferred lights through a generated dispatch on the G-buffer's
shading-model id, the forward pass in its loop over the lights. An optional
``vec3 <ambient_function>(Surface s, vec3 irradiance)`` answers the ambient light (default:
``albedo * irradiance``). Register with ``@deferred.interfaces.registry.shading_models.register`` or the
entry-point group ``deferred.shading_models``; only the models a scene uses are compiled.

**G-buffer data** is extra per-pixel data (a strand tangent, a toon ramp row) in a render target
of its own. A material declares it (``Material.gbuffer_data``) and so may a shading model (what it
reads, added to every material using it). The scene's G-buffer layout is composed from the
materials present (:func:`compose_layout`): a scene of standard objects keeps the 20-byte core.
In GLSL the data is a ``vec4`` field of ``Surface.data`` under its name: the material's surface
function sets it, the G-buffer pass writes it, the lights read it back, and the forward pipeline
passes it straight through.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

import moderngl

from deferred.errors import InputError
from deferred.gbuffer.layout import GBUFFER_COLOR_TARGETS, GBUFFER_TARGETS
from deferred.gl.target_spec import TargetSpec

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.interfaces.material import Material

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


class ShadingModel:
    """A BRDF the lights call (see the module documentation)."""

    name: ClassVar[str]
    glsl_file: ClassVar[str] = ""
    glsl_function: ClassVar[str] = ""
    ambient_function: ClassVar[str | None] = None
    gbuffer_data: ClassVar[tuple[GBufferData, ...]] = ()
    shader_root: ClassVar[Traversable | Path | None] = None
    type_id: ClassVar[int] = 0  # set by the registry; stored in the G-buffer

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        """Samplers the model's GLSL reads (e.g. a ramp), bound wherever lights are evaluated."""
        return {}


# The G-buffer's id channel (a half float) holds shading model * MATERIAL_IDS + material id:
# integers up to 2048 are exact in a half, so 63 materials and 31 shading models fit.
MATERIAL_IDS = 64
MAX_MATERIAL_ID = MATERIAL_IDS - 1
MAX_SHADING_MODEL_ID = 2047 // MATERIAL_IDS


def surface_id(material_id: int, shading_model_id: int) -> int:
    """The value an object writes to the G-buffer's id channel (``gbuffer/layout.glsl``)."""
    if not 0 < material_id <= MAX_MATERIAL_ID or not 0 < shading_model_id <= MAX_SHADING_MODEL_ID:
        raise ValueError(f"ids out of range: material {material_id}, shading model "
                         f"{shading_model_id}")
    return shading_model_id * MATERIAL_IDS + material_id


def split_surface_id(value):
    """(material id, shading model id) of G-buffer id values (numpy arrays or numbers)."""
    return value % MATERIAL_IDS, value // MATERIAL_IDS


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


def material_data(material: Material) -> tuple[GBufferData, ...]:
    """The data ``material``'s objects write: its own and its shading model's, by name
    (kept on the material: its class, model and parameters never change)."""
    cached = material.__dict__.get("_gbuffer_data")
    if cached is None:
        cached = material.__dict__["_gbuffer_data"] = _material_data(material)
    return cached


def _material_data(material: Material) -> tuple[GBufferData, ...]:
    from deferred.interfaces import registry

    model = registry.shading_models.get(material.shading_model)
    merged: dict[str, GBufferData] = {}
    for data in (*model.gbuffer_data, *material.gbuffer_data):
        if data.name in merged and merged[data.name] != data:
            raise InputError(f"material {material.name}: G-buffer data '{data.name}' is declared "
                             f"twice with different formats")
        merged[data.name] = data
    return tuple(merged.values())


def compose_layout(materials: Iterable[Material]) -> GBufferLayout:
    """The layout for a scene's materials; one name declared two ways is an error."""
    data: dict[str, GBufferData] = {}
    owners: dict[str, str] = {}
    for material in materials:
        for entry in material_data(material):
            if entry.name in data and data[entry.name] != entry:
                raise InputError(f"G-buffer data '{entry.name}' is declared as {entry.format} "
                                 f"{entry.channels} by {material.name} and as "
                                 f"{data[entry.name].format} {data[entry.name].channels} by "
                                 f"{owners[entry.name]}")
            data.setdefault(entry.name, entry)
            owners.setdefault(entry.name, material.name)
    return GBufferLayout(data)


def shading_dispatch_glsl(models: list[type[ShadingModel]]) -> str:
    """GLSL of ``shade_light`` and ``shade_ambient``: the scene's models, by id."""
    lines = [f'#include "{cls.glsl_file}"' for cls in models]
    lines.append("vec3 shade_light(Surface s, vec3 L, vec3 V, vec3 radiance) {")
    lines += [f"    if (s.shading_model == {cls.type_id}) "
              f"return {cls.glsl_function}(s, L, V, radiance);" for cls in models]
    lines += ["    return vec3(0.0);", "}"]
    lines.append("vec3 shade_ambient(Surface s, vec3 irradiance) {")
    lines += [f"    if (s.shading_model == {cls.type_id}) "
              f"return {cls.ambient_function}(s, irradiance);"
              for cls in models if cls.ambient_function]
    lines += ["    return s.albedo * irradiance;", "}"]
    return "\n".join(lines) + "\n"
