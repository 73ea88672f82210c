// Fewer dashes along strands (not in the paper): a shell stands for a slab of the fur, 1 / slabs
// of its depth, but samples the strands at one height, so a strand the eye crosses at a slant
// shows as a dash on each shell with gaps between (Figure 2.20's knitted look). Two samples
// instead, a quarter of the slab above and below the shell, each at the base point under where
// the view ray through the fragment is at that height (moved along the ray's slant over the
// surface, less the comb's lean the shells follow): a box filter along the ray within the slab.
// The mean coverage is that of one sample.
#include "common/object_transform.glsl"
#include "materials/techniques/fur.glsl"

#include "materials/revie_fur/comb.glsl"

uniform float u_fur_length;
uniform vec3 u_fur_scale;

// view_position, comb_view: view space; length_scale: the vertex colour alpha; slab: the
// shell's share of the fur's depth.
vec2 fur_sample_slab(vec3 fur_position, vec3 fur_normal, float h, float slab,
                     vec3 view_position, vec3 comb_view, float length_scale) {
    mat3 to_object = transpose(u_model_normal_matrix) * transpose(mat3(u_view));
    vec3 N = normalize(fur_normal);
    vec3 V = normalize(to_object * normalize(-view_position));
    float vn = max(dot(V, N), 0.25);  // grazing: the slant's reach is capped at 4 slab depths
    vec3 lean = to_object * comb_view * u_comb_strength;
    lean -= dot(lean, N) * N;
    float depth = 0.25 * slab * u_fur_length * length_scale;  // object units
    // d(base point) / d(height) along the ray: its slant, less the shells' lean (d offset / dh
    // of materials/techniques/shells.glsl is about (N + 2 h comb) for a small lean)
    vec3 shift = ((V - dot(V, N) * N) / vn - 2.0 * h * lean) * depth * u_fur_scale;
    vec3 dx = dFdx(fur_position);
    vec3 dy = dFdy(fur_position);
    return 0.5 * (fur_sample_grad(fur_position + shift, N, h + 0.25 * slab, dx, dy)
                + fur_sample_grad(fur_position - shift, N, h - 0.25 * slab, dx, dy));
}
