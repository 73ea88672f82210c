// Blinn-Phong with the G-buffer's quantities (albedo, specular intensity and exponent).
#include "common/surface.glsl"

vec3 blinn_phong(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    if (n_dot_l <= 0.0) return vec3(0.0);
    vec3 H = normalize(L + V);
    float specular = s.specular_intensity * pow(max(dot(s.normal, H), 0.0), s.specular_exponent);
    return radiance * n_dot_l * (s.albedo + vec3(specular));
}
