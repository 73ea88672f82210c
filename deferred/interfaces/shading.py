"""Shading models and the per-pixel data materials declare (Unreal's shading-model id and custom
data, Filament's shading models).

A **shading model** is a BRDF in one GLSL file, defining
``vec3 <glsl_function>(Surface s, vec3 L, vec3 V, vec3 radiance)``: the light reflected toward
``V`` (unit, to the viewer) by a surface lit from ``L`` (unit, to the light) with ``radiance``.
Both pipelines call it: the deferred lights through a generated dispatch on the G-buffer's
shading-model id, the forward pass in its loop over the lights. An optional
``vec3 <ambient_function>(Surface s, vec3 irradiance)`` answers the ambient light (default:
``albedo * irradiance``), and an optional ``vec3 <environment_function>(Surface s, vec3 V,
Environment e)`` the image-based light (``lighting/environment.glsl``: its irradiance and its
prefiltered radiance by roughness; default: the ambient answer to its irradiance at the
normal, times the surface's occlusion). An optional ``vec3 <area_function>(Surface s, vec3 V,
AreaLight a)`` in its own ``area_file`` answers area lights (``lighting/area.glsl``: the
polygon's clipped cosine integral, a GGX lobe's share of it by linearly transformed cosines);
default: the light taken as a point light along its vector irradiance
(``area_as_point_light``). The area answers are compiled only into scenes with area lights.

A model may **split** its light into diffuse and specular: ``diffuse_function`` and
``specular_function`` (each ``vec3 f(Surface s, vec3 L, vec3 V, vec3 radiance)``, their sum
its answer). A scene with such a model compiles with ``SPLIT_LIGHTING``: the generated
``shade_light`` adds the model's diffuse part (and the whole of its ambient answer) into the
global ``split_light_diffuse``, which the lighting passes write into the ``diffuse_light``
target beside the light accumulation (a screen-space effect on the diffuse light alone: the
subsurface blur); its area answer adds its own diffuse part. A scene without one keeps its
targets and its programs as they were. A model with a ``transmission_function`` (``vec3
f(Surface s, vec3 L, vec3 V, vec3 radiance, float thickness)``: light through the surface from
a light behind it, ``thickness`` the distance the light's shadow map puts between the point
and the surface the light sees first) is called by the shadowed lights for each light before
its shadow is applied (``SURFACE_TRANSMISSION``).
Register with ``@deferred.api.shading_models.register`` or the entry-point group
``deferred.shading_models``; only the models a scene uses are compiled.

**G-buffer data** is extra per-pixel data (a strand tangent, a toon ramp row) in a render target
of its own. A material declares it (``Material.gbuffer_data``) and so may a shading model (what it
reads, added to every material using it). The scene's G-buffer layout is composed from the
materials present (:func:`compose_layout`): a scene of standard objects keeps the 20-byte core.
In GLSL the data is a ``vec4`` field of ``Surface.data`` under its name: the material's surface
function sets it, the G-buffer pass writes it, the lights read it back, and the forward pipeline
passes it straight through.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

import moderngl

from deferred.gbuffer.layout import GBufferData

if sys.version_info >= (3, 11):
    from importlib.resources.abc import Traversable
else:  # Python 3.10
    from importlib.abc import Traversable

if TYPE_CHECKING:
    from deferred.core.frame import Frame

class ShadingModel:
    """A BRDF the lights call (see the module documentation)."""

    name: ClassVar[str]
    glsl_file: ClassVar[str] = ""
    glsl_function: ClassVar[str] = ""
    ambient_function: ClassVar[str | None] = None
    environment_function: ClassVar[str | None] = None
    # the area-light answer and its file (compiled only where the scene has area lights)
    area_function: ClassVar[str | None] = None
    area_file: ClassVar[str | None] = None
    # the answer split into diffuse and specular (both set: the scene splits its light)
    diffuse_function: ClassVar[str | None] = None
    specular_function: ClassVar[str | None] = None
    # light through the surface from behind it (thickness from the shadow maps)
    transmission_function: ClassVar[str | None] = None

    @classmethod
    def splits_light(cls) -> bool:
        """Whether the model answers diffuse and specular apart (``SPLIT_LIGHTING``)."""
        return bool(cls.diffuse_function and cls.specular_function)
    # the most bytes a pixel the model's surfaces may take in the G-buffer (the core and its
    # data): `deferred info` states it, and a model's data over it is refused (None: no budget)
    gbuffer_budget: ClassVar[int | None] = None
    gbuffer_data: ClassVar[tuple[GBufferData, ...]] = ()
    shader_root: ClassVar[Traversable | Path | None] = None
    type_id: ClassVar[int] = 0  # set by the registry; stored in the G-buffer

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        """Samplers the model's GLSL reads (e.g. a ramp), bound wherever lights are evaluated."""
        return {}


ENVIRONMENT_GLSL = "lighting/environment.glsl"
SPLIT_DEFINE = "SPLIT_LIGHTING"  # a model of the scene splits its light
TRANSMISSION_DEFINE = "SURFACE_TRANSMISSION"  # a model of the scene takes light through it
AREA_GLSL = "lighting/area.glsl"


def scene_splits_light(models) -> bool:
    """Whether a scene of ``models`` splits its light (``SPLIT_LIGHTING``)."""
    return any(cls.splits_light() for cls in models)


def scene_transmits(models) -> bool:
    """Whether a model of ``models`` takes light through it (``SURFACE_TRANSMISSION``)."""
    return any(cls.transmission_function for cls in models)


def _counted(name: str) -> list[str]:
    # under the define the scene compiles with where it has such a model (a program built
    # from every model without it, as a test of the shader files does, leaves it out)
    return [f"#ifdef {SPLIT_DEFINE}", f"        split_light_diffuse += {name};", "#endif"]


def _light_answer(cls: type[ShadingModel], split: bool) -> list[str]:
    if split and cls.splits_light():
        return [f"    if (s.shading_model == {cls.type_id}) {{",
                f"        vec3 diffuse = {cls.diffuse_function}(s, L, V, radiance);",
                *_counted("diffuse"),
                f"        return diffuse + {cls.specular_function}(s, L, V, radiance);",
                "    }"]
    return [f"    if (s.shading_model == {cls.type_id}) "
            f"return {cls.glsl_function}(s, L, V, radiance);"]


def _ambient_answer(cls: type[ShadingModel], split: bool) -> list[str]:
    call = f"{cls.ambient_function}(s, irradiance)" if cls.ambient_function else \
        "s.albedo * irradiance"
    if split and cls.splits_light():  # all of it diffuse
        return [f"    if (s.shading_model == {cls.type_id}) {{",
                f"        vec3 ambient = {call};",
                *_counted("ambient"),
                "        return ambient;",
                "    }"]
    if not cls.ambient_function:
        return []
    return [f"    if (s.shading_model == {cls.type_id}) return {call};"]


def shading_dispatch_glsl(models: list[type[ShadingModel]], area: bool = False) -> str:
    """GLSL of ``shade_light``, ``shade_ambient`` and ``shade_environment``: the scene's
    models, by id; with ``area`` (the scene has area lights), ``shade_area`` too; where a model
    splits its light, its diffuse part counted in ``split_light_diffuse``; where one takes
    light through it, ``shade_transmission``."""
    split = scene_splits_light(models)
    lines = [f'#include "{ENVIRONMENT_GLSL}"']
    lines += [f'#include "{cls.glsl_file}"' for cls in models]
    lines.append("vec3 shade_light(Surface s, vec3 L, vec3 V, vec3 radiance) {")
    for cls in models:
        lines += _light_answer(cls, split)
    lines += ["    return vec3(0.0);", "}"]
    lines.append("vec3 shade_ambient(Surface s, vec3 irradiance) {")
    for cls in models:
        lines += _ambient_answer(cls, split)
    lines += ["    return s.albedo * irradiance;", "}"]
    lines.append("vec3 shade_environment(Surface s, vec3 V, Environment e) {")
    lines += [f"    if (s.shading_model == {cls.type_id}) "
              f"return {cls.environment_function}(s, V, e);"
              for cls in models if cls.environment_function]
    lines += ["    return shade_ambient(s, environment_irradiance(e, s.normal) * s.occlusion);",
              "}"]
    if area:
        lines.append(f'#include "{AREA_GLSL}"')
        lines += [f'#include "{cls.area_file}"' for cls in models
                  if cls.area_function and cls.area_file]
        lines.append("vec3 shade_area(Surface s, vec3 V, AreaLight a) {")
        lines += [f"    if (s.shading_model == {cls.type_id}) "
                  f"return {cls.area_function}(s, V, a);"
                  for cls in models if cls.area_function]
        lines += ["    return area_as_point_light(s, V, a);", "}"]
    if scene_transmits(models):
        lines.append("vec3 shade_transmission(Surface s, vec3 L, vec3 V, vec3 radiance, "
                     "float thickness) {")
        lines += [f"    if (s.shading_model == {cls.type_id}) "
                  f"return {cls.transmission_function}(s, L, V, radiance, thickness);"
                  for cls in models if cls.transmission_function]
        lines += ["    return vec3(0.0);", "}"]
    return "\n".join(lines) + "\n"
