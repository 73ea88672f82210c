// Kajiya-Kay strand shading (Silva et al. Eq. 6, after Kajiya and Kay 1989):
//   C_d = K_color |T x L|,  C_s = K_s [(T.L)(T.E) + |T x L||T x E|]^p
// T the strand tangent (G-buffer data strand_tangent), L toward the light, E the camera
// direction (from the eye toward the point, -V): the specular term peaks where V lies on the
// cone of mirror directions around the strand. Silva's shadow factor gamma belongs to the
// material (it darkens the albedo with depth into the fur).
#include "common/surface.glsl"
#include "materials/techniques/strand_tangent.glsl"

vec3 kajiya_kay(Surface s, vec3 L, vec3 V, vec3 radiance) {
    vec3 T = strand_tangent_decode(s.data.strand_tangent);
    vec3 E = -V;
    float t_dot_l = dot(T, L);
    float t_dot_e = dot(T, E);
    float sin_tl = sqrt(max(1.0 - t_dot_l * t_dot_l, 0.0));
    float sin_te = sqrt(max(1.0 - t_dot_e * t_dot_e, 0.0));
    float diffuse = sin_tl;
    float cone = max(t_dot_l * t_dot_e + sin_tl * sin_te, 0.0);
    float specular = s.specular_intensity * pow(cone, s.specular_exponent);
    return radiance * (s.albedo * diffuse + vec3(specular));
}
