// shell_fur's debug views (FUR_DEBUG_*; materials/shell_fur/__init__.py lists them): what a layer
// fragment shows instead of its fur. Returns false where the fur is drawn.
#include "materials/shell_fur/clump.glsl"

vec3 clump_hue(vec2 centre) {
    vec3 h = fract(sin(vec3(dot(centre, vec2(127.1, 311.7)), dot(centre, vec2(269.5, 183.3)),
                            dot(centre, vec2(419.2, 371.9)))) * 43758.5453);
    return 0.25 + 0.75 * h;
}

bool fur_debug_view(vec2 uv, vec2 strands, bool kept, float shell_count, out vec4 color) {
    color = vec4(0.0);
#if defined(FUR_DEBUG_WETNESS)
    // the wetness mask on the skin: a colour per clump, as bright as it is wet; dry black
    vec4 mask = textureLod(u_wetness_mask, uv, 0.0);
    color = vec4(mask.a > 0.0 ? clump_hue(mask.rg) * (0.25 + 0.75 * mask.a) : vec3(0.0), 1.0);
    return true;
#elif defined(FUR_DEBUG_SHELL_COUNT)
    color = vec4(mix(vec3(0.1, 0.2, 1.0), vec3(1.0, 0.15, 0.1), shell_count), 1.0);
    return true;
#elif defined(FUR_DEBUG_SINGLE_SHELL)
    // the cut through the strands, opaque, after clumping (Algorithm 2's ignored fragments too)
    if (!kept || strands.x <= 0.02) discard;
    color = vec4(vec3(1.0), 1.0);
    return true;
#else
    return false;
#endif
}
