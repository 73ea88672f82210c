// The volume lights of one light list at a surface point: the deferred tiled and clustered
// shading and Forward+ (deferred.light_lists).
//
// A list holds the lights that touch its tile or cluster; most miss any one point of it, and
// the sphere test is far cheaper than the light. Where a fragment shader runs as SIMD lanes
// (llvmpipe) the light's arithmetic still runs for every entry; what a missed entry saves is
// its four record fetches. Testing a chunk of entries first and then evaluating only the lights
// that reach some lane (a bit mask per chunk) was tried: on llvmpipe it was slower at every
// light count (lights.toml at 640x360: the tiled shading 46 -> 54 ms at 1024 lights, and a
// Forward+ floor 9 -> 29 ms at 16), since a light reaching one pixel of a SIMD group reaches
// most of them. Reading the list four entries a fetch (an RGBA32UI texture, the loop unrolled
// by four with a test of each entry against the length) was slower too: the tiled shading
// 42-49 -> 61-86 ms at 1024 lights, a Forward+ floor 71-73 -> 111-125 ms.
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "lights/light_lists.glsl"

vec3 evaluate_listed_lights(int list, Surface s, vec3 P, vec3 V) {
    vec3 total = vec3(0.0);
    int length = light_list_length(list);
    for (int k = 0; k < length; ++k) {
        int index = light_list_light(list, k);
        if (light_reaches(index, P)) total += evaluate_volume_light(fetch_light(index), s, P, V);
    }
    return total;
}
