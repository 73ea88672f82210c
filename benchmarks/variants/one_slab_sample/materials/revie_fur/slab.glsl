// benchmarks/fur_shading.py's cut-out of materials/revie_fur/slab.glsl: one sample at the shell's
// own height (revie_fur before the slab's box filter), to time what the second sample costs.
#include "common/object_transform.glsl"
#include "materials/techniques/fur.glsl"

#include "materials/revie_fur/comb.glsl"

uniform float u_fur_length;
uniform vec3 u_fur_scale;

vec2 fur_sample_slab(vec3 fur_position, vec3 fur_normal, float h, float slab,
                     vec3 view_position, vec3 comb_view, float length_scale) {
    return fur_sample(fur_position, fur_normal, h);
}
