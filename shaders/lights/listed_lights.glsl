// The volume lights of one light list at a surface point: the deferred tiled and clustered
// shading and Forward+ (deferred.light_lists).
//
// A list holds the lights that touch its tile or cluster; most miss any one point of it
// (lights.toml at 1024 lights, 640x360: 21.6 entries a pixel in the 8x8 tiled lists, 31.5 in
// 16x16 ones, 13.2 reaching the pixel, 14.5 some pixel of its 4x2 block, the width of a
// 256-bit SIMD vector). Where a fragment shader runs as SIMD lanes (llvmpipe) a light's
// arithmetic runs for the whole block where any lane is reached, and is skipped where none
// is. Each entry is one texel, its light's sphere and index; a light that reaches the pixel
// reads its colour (and what else its type needs) from the light buffer
// (lights/light_lists.glsl). Cut-outs of this loop at 256 lights, 640x360
// (benchmarks/shader_ab.py, the pass 22 ms): the loop's sphere fetches and tests 3.2 ms, the
// evaluations 7.5 ms, of which Blinn-Phong's pow 3.4; at 1024 lights pow is 8.7 of 39 ms.
// Tried and slower or no faster on llvmpipe (benchmarks/README.md): a bit mask of reached
// entries with a loop over its set bits; four indices a fetch; the loop unrolled by two; an
// `if` around pow for negligible highlights (the compiler makes it a select).
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "lights/light_lists.glsl"

vec3 evaluate_listed_lights(int list, Surface s, vec3 P, vec3 V) {
    vec3 total = vec3(0.0);
    int length = light_list_length(list);
    int first = light_list_first_slot(list);
    for (int k = 0; k < length; ++k) {
        // the sphere test is far cheaper than the light; most entries miss the point
        ListedLight listed = listed_light(first + k);
        vec3 to_light = listed.sphere.xyz - P;
        if (dot(to_light, to_light) <= listed.sphere.w * listed.sphere.w)
            total += evaluate_volume_light(listed_light_record(listed), s, P, V);
    }
    return total;
}
