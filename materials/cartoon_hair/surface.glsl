// Cartoon hair (Costigan 4.3.3-4.3.6): the head in its skin colour and the hair's tubes in the
// hair colour, both shaded by the toon_strands model through the material's X-toon ramp (the
// G-buffer datum toon_ramp). The tubes write their strand tangent (strand_tangent: the
// specular follows the strand) and their strand and clump into strand_id (1 + the object's
// first strand id + the strand's index, and the same of the strand's clump; 0 on the head), so
// the edges effect outlines clumps where they overlap and the silhouette strokes find their
// own strand. The head writes no tangent (the skin's highlight is its normal's). The tubes
// carry the strand's index and its clump's in the comb slot (deferred.materials.cartoon_hair).
#include "common/surface.glsl"
#include "materials/shading_models/toon_strands.glsl"

uniform vec3 u_color;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
uniform float u_ramp_row;
uniform bool u_hair;
uniform float u_strand_base;  // the object's first strand id (an id range a hair object)

// The direction along the strand (uv.x, root to tip) at this fragment, from the screen
// derivatives of the position and the uv: each tube triangle has an edge along the strand at
// constant uv.y, so d(position)/d(uv.x) at constant uv.y is that edge's direction.
vec3 strand_direction(SurfaceInput i) {
    vec3 dp_dx = dFdx(i.position);
    vec3 dp_dy = dFdy(i.position);
    vec2 duv_dx = dFdx(i.uv);
    vec2 duv_dy = dFdy(i.uv);
    vec3 along = dp_dx * duv_dy.y - dp_dy * duv_dx.y;
    float determinant = duv_dx.x * duv_dy.y - duv_dy.x * duv_dx.y;
    along *= determinant < 0.0 ? -1.0 : 1.0;
    float length_along = length(along);
    // a cap (every vertex at one uv.x): the strand runs along the cap's normal
    return length_along > 1e-20 ? along / length_along : i.normal;
}

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = i.normal;
    s.data.toon_ramp = vec4(u_ramp_row, 0.0, 0.0, 0.0);
    vec3 along = strand_direction(i);  // outside the branch: derivatives need every lane
    s.data.strand_tangent = u_hair ? strand_tangent_encode(along) : toon_strands_no_tangent();
    // every vertex of a tube holds its strand: interpolation only rounds it
    float strand = floor(i.comb.x + 0.5);
    float clump = floor(i.comb.z + 0.5);
    s.data.strand_id = u_hair ? vec4(u_strand_base + strand + 1.0, u_strand_base + clump + 1.0,
                                     0.0, 0.0)
                              : vec4(0.0);
    return s;
}
