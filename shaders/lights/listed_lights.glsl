// The volume lights of one light list at a surface point: the deferred tiled and clustered
// shading and Forward+ (deferred.light_lists).
//
// A list holds the lights that touch its tile or cluster; most miss any one point of it
// (lights.toml at 1024 lights: 31.5 entries a pixel, 13.2 reaching it, 14.5 reaching some pixel
// of its 4x2 block, the width of a 256-bit SIMD vector). Where a fragment shader runs as SIMD
// lanes (llvmpipe) the light's arithmetic still runs for every entry; a missed entry saves its
// record fetches. With parts of this loop cut out (1024 lights, 640x360, a pass of 64 ms): the
// list words cost about 10 ms, the sphere tests 15-20, the evaluations 25-30. Two ways of
// evaluating fewer lights were tried and were slower on llvmpipe at every light count, the
// loops and gathers they add costing more than the evaluations saved: testing 32 entries
// first and evaluating only the set bits of the mask, in a loop whose trip count differs
// between lanes (the tiled shading 46 -> 54 ms at 1024 lights, and 54-68 -> 85-109 ms in a
// second A/B run; a Forward+ floor 9 -> 29 ms at 16 lights); and reading the list four entries
// a fetch from an RGBA32UI texture with the loop unrolled by four (42-49 -> 61-86 ms; a
// Forward+ floor 71-73 -> 111-125 ms).
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "lights/light_lists.glsl"

vec3 evaluate_listed_lights(int list, Surface s, vec3 P, vec3 V) {
    vec3 total = vec3(0.0);
    int length = light_list_length(list);
    int first = light_list_first_slot(list);
    for (int k = 0; k < length; ++k) {
        // the sphere test is far cheaper than the light; most entries miss the point
        vec4 sphere = listed_light_sphere(first + k);
        vec3 to_light = sphere.xyz - P;
        if (dot(to_light, to_light) <= sphere.w * sphere.w)
            total += evaluate_volume_light(listed_light_record(first + k, sphere), s, P, V);
    }
    return total;
}
