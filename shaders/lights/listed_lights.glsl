// The volume lights of one light list at a surface point: the deferred tiled and clustered
// shading and Forward+ (deferred.light_lists).
//
// A list holds the lights that touch its tile or cluster; most miss any one point of it
// (lights.toml at 1024 lights: 31.5 entries a pixel, 13.2 reaching it, 14.5 reaching some pixel
// of its 4x2 block, the width of a 256-bit SIMD vector). Where a fragment shader runs as SIMD
// lanes (llvmpipe) a light's arithmetic runs for the whole block where any lane is reached, and
// is skipped where none is. Each entry is its light's sphere, then its colour: one texel a
// listed light, one more for each that reaches (lights/light_lists.glsl). Cut-outs of this
// loop at 1024 lights, 640x360, frames interleaved in one process (benchmarks/shader_ab.py;
// the pass 56-60 ms with index lists): the evaluations beyond their record fetches 18-20 ms,
// another texel fetch an entry 4-11 ms; the G-buffer read and the full-screen lights 11-13 ms.
// Tried and slower on llvmpipe (benchmarks/README.md): a bit mask of reached entries with a
// loop over its set bits; four indices a fetch; the sphere in the list but the colour through
// the index.
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
