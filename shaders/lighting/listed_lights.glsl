// The volume lights of one light list at a surface point: the deferred tiled and clustered
// shading and Forward+ (deferred.lighting.culling).
//
// A list holds the lights that touch its tile or cluster; many miss any one point of it
// (lights.toml at 1024 lights, 640x360: 21.6 entries a pixel in the 8x8 tiled lists, 31.5 in
// 16x16 ones, 13.2 reaching the pixel). Each entry is one texel, its light's sphere and index;
// a light that reaches the pixel reads its colour (and what else its type needs) from the
// light buffer (lighting/light_lists.glsl).
//
// Where a fragment shader runs as SIMD lanes under masks (llvmpipe: Mesa 22.3's gallivm), an
// `if` skips nothing: its body runs for every block of lanes, masked. So every entry costs its
// light's whole evaluation whether it reaches the pixel or not (an `if` that never holds costs
// as much as this one, benchmarks/README.md), and only a loop's trip count saves work: the
// cost is entries x (fetch + sphere test + evaluation). The loop is a do-while, since a for
// loop runs its body once more than its trips, masked, to find every lane done
// (benchmarks/README.md). The sphere test stays: it costs
// nothing measurable there and spares the evaluation on GPUs that branch.
// Tried and slower or no faster on llvmpipe (benchmarks/README.md): a bit mask of reached
// entries with a loop over its set bits; a loop that skips to the next entry some lane (or,
// with GL_ARB_shader_group_vote, any lane) reaches, evaluating only those; four indices a
// fetch; the loop unrolled by two; an `if` around pow for negligible highlights.
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "lighting/light_lists.glsl"
#include "generated/listed_lights.glsl"

vec3 evaluate_listed_lights(int list, Surface s, vec3 P, vec3 V) {
    // the loops, a do-while per volume light type: deferred.lighting.dispatch.listed_dispatch_glsl
    return evaluate_listed_slots(light_list_first_slot(list), light_list_length(list), s, P, V);
}
