"""The GLSL generated for a scene: light and shading-model dispatch, the G-buffer data's
struct, reads and writes. Only what the scene uses goes in (a plugin the scene does not use is
never compiled)."""

from __future__ import annotations

from collections.abc import Iterable

from deferred.gbuffer.layout import (
    DATA_FETCH_FILE,
    DATA_STRUCT_FILE,
    GBufferLayout,
    data_fetch_glsl,
    data_struct_glsl,
    data_write_file,
    data_write_glsl,
)
from deferred.gbuffer.surface_id import SURFACE_ID_FILE, surface_id_glsl
from deferred.interfaces.light import Light
from deferred.interfaces.material import Material
from deferred.interfaces.shading import ShadingModel, shading_dispatch_glsl
from deferred.lighting.dispatch import (
    DISPATCH_FILE,
    LISTED_DISPATCH_FILE,
    SHADING_DISPATCH_FILE,
    light_dispatch_glsl,
    listed_dispatch_glsl,
)


def generated_glsl(light_types: list[type[Light]], shading_models: list[type[ShadingModel]],
                   layout: GBufferLayout, materials: Iterable[Material]) -> dict[str, str]:
    """Virtual file name -> GLSL text, for :meth:`ShaderLibrary.set_virtual_file`."""
    names = list(layout.data)
    files = {
        DISPATCH_FILE: light_dispatch_glsl(light_types),
        LISTED_DISPATCH_FILE: listed_dispatch_glsl(light_types),
        SHADING_DISPATCH_FILE: shading_dispatch_glsl(
            shading_models, area=any(cls.area for cls in light_types)),
        DATA_STRUCT_FILE: data_struct_glsl(names),
        DATA_FETCH_FILE: data_fetch_glsl(names),
        data_write_file([]): data_write_glsl([]),
        SURFACE_ID_FILE: surface_id_glsl(),
    }
    for material in materials:
        written = [data.name for data in material.written_data()]
        files[data_write_file(written)] = data_write_glsl(written)
    return files
