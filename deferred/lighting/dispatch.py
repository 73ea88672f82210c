"""The generated GLSL that calls the scene's light types: one dispatch by type id, loops over
each type's range of the light buffer, and the loops over one light list's entries."""

from __future__ import annotations

from deferred.interfaces.light import Light
from deferred.names import LightVolume

DISPATCH_FILE = "generated/lights.glsl"
LISTED_DISPATCH_FILE = "generated/listed_lights.glsl"  # after lighting/light_lists.glsl only
SHADING_DISPATCH_FILE = "generated/shading_models.glsl"
RANGE_UNIFORM_PREFIX = "u_light_range_"
# Full-screen lights a frame may have: their records are also a uniform array
# (``u_fullscreen_lights``, four vec4s each), which every pixel reads in the list and forward
# paths: llvmpipe reads a uniform faster than a texel (benchmarks/README.md, "What llvmpipe
# skips").
FULLSCREEN_LIGHT_CAPACITY = 16
FULLSCREEN_UNIFORM = "u_fullscreen_lights"
FULLSCREEN_LIGHTS_FILE = "common/fullscreen_lights.glsl"


def light_range_uniform(light_type: type[Light]) -> str:
    """The ``ivec2`` uniform holding (first record, count) of one light type this frame: named
    by type id, since a plugin's type name need not be a GLSL identifier."""
    return f"{RANGE_UNIFORM_PREFIX}{light_type.type_id}"


def light_data_glsl(light_type: type[Light]) -> list[str]:
    """GLSL of a type's own data (``Light.data``): ``struct <glsl_function>_Data`` with a
    ``vec4`` field per datum, and ``<glsl_function>_data(light)`` reading them from the light
    buffer (``light_datum``, common/light_buffer.glsl). None for a type without data."""
    if not light_type.data:
        return []
    name = light_type.glsl_function
    fields = [f"    vec4 {datum.name};  // {datum.description}" for datum in light_type.data]
    reads = ", ".join(f"light_datum(light, {k})" for k in range(len(light_type.data)))
    return [f"struct {name}_Data {{", *fields, "};",
            f"{name}_Data {name}_data(LightRecord light) {{",
            f"    return {name}_Data({reads});", "}"]


def light_dispatch_glsl(light_types: list[type[Light]]) -> str:
    """GLSL of the light dispatch (and the shading models' dispatch, which the lights call):

    - each type's data struct and reader, where it declares data (:func:`light_data_glsl`),
      before its file;
    - ``LIGHT_RANGE_<name>``: each type's range uniform (first record, count), defined for
      the scene's types whose name is an identifier;
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
    if any(cls.data for cls in light_types):
        lines.append('#include "common/light_buffer.glsl"')  # light_datum
    for cls in light_types:
        lines += [*light_data_glsl(cls), f'#include "{cls.glsl_file}"']
    lines += [f"uniform ivec2 {light_range_uniform(cls)};" for cls in light_types]
    # a type's range by its name, where the name is a GLSL identifier: `#ifdef LIGHT_RANGE_x`
    # holds where the scene has lights of type x (a material's own loop over one type)
    lines += [f"#define LIGHT_RANGE_{cls.name} {light_range_uniform(cls)}"
              for cls in light_types if cls.name.isidentifier() and cls.name.isascii()]

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

    fullscreen = [cls for cls in light_types if cls.volume == LightVolume.FULLSCREEN]
    volumes = [cls for cls in light_types if cls.volume != LightVolume.FULLSCREEN]
    lines += switch("evaluate_light", light_types)
    lines += switch("evaluate_volume_light", volumes)
    lines += loops("evaluate_fullscreen_lights", fullscreen, "fullscreen_light")
    lines += loops("evaluate_volume_lights", volumes, "fetch_light")
    return "\n".join(lines) + "\n"


def listed_dispatch_glsl(light_types: list[type[Light]]) -> str:
    """GLSL of ``evaluate_listed_slots(first, length, s, P, V)``: the volume lights of one light
    list (``lighting/listed_lights.glsl``), a do-while loop per volume type in type order.

    A list holds its lights in light order (the culling's), and the light buffer its types in
    type order (:class:`~deferred.lighting.buffer.LightBuffer`), so each type's entries follow one
    another: each loop runs over its type's and calls its function, where a switch on the type
    per entry ran every type's evaluation for every entry on llvmpipe (an `if` skips nothing
    there; benchmarks/README.md has the cost). A loop but the last stops at the first entry
    past its type's range, whose evaluation runs masked once on llvmpipe."""
    volumes = sorted((cls for cls in light_types if cls.volume != LightVolume.FULLSCREEN),
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
