// Hair shading (Marschner et al. 2003 in Karis's 2016 real-time form: materials/techniques/hair_bsdf.glsl)
// for strands: R, TT and TRT lobes about the strand tangent T (G-buffer data strand_tangent,
// root to tip) and a multiple-scattering lobe; the ambient answers with that lobe averaged over
// directions. The surface's specular_exponent carries the longitudinal roughness beta
// (radians) and its specular_intensity scales R.
#include "common/surface.glsl"
#include "materials/techniques/strand_tangent.glsl"
#include "materials/techniques/hair_bsdf.glsl"

// The skin under the strands hides a light well below its horizon: the lobes hold for a lone
// fibre, and without it a light behind an object would shine through its body onto the fur
// facing the eye. The fur layer still takes light a little past the horizon (the tips at a
// back-lit silhouette, where TT glows).
float marschner_skin(vec3 normal, vec3 L) {
    return smoothstep(-0.35, 0.15, dot(normal, L));
}

vec3 marschner(Surface s, vec3 L, vec3 V, vec3 radiance) {
    vec3 T = strand_tangent_decode(s.data.strand_tangent);
    return radiance * marschner_skin(s.normal, L) *
        hair_bsdf(T, L, V, s.albedo, s.specular_exponent, s.specular_intensity);
}

vec3 marschner_ambient(Surface s, vec3 irradiance) {
    return hair_ambient(s.albedo, irradiance);
}
