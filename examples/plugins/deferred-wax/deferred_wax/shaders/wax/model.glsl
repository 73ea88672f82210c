// Wax: wrapped diffuse, (N.L + w) / (1 + w), past the terminator; a Blinn-Phong highlight; light
// through a thickness t from a light behind, albedo * exp(-t / mean free path) times the back's
// wrapped cosine.
#include "common/surface.glsl"

vec3 wax_diffuse(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float wrap = s.data.wax.x;
    return radiance * s.albedo * max((dot(s.normal, L) + wrap) / (1.0 + wrap), 0.0);
}

vec3 wax_specular(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    if (n_dot_l <= 0.0) return vec3(0.0);
    vec3 H = normalize(L + V);
    return radiance * n_dot_l * s.specular_intensity *
           pow(max(dot(s.normal, H), 0.0), s.specular_exponent);
}

vec3 wax(Surface s, vec3 L, vec3 V, vec3 radiance) {
    return wax_diffuse(s, L, V, radiance) + wax_specular(s, L, V, radiance);
}

// thickness: how far the light's shadow map puts the surface it sees first (1e30: none)
vec3 wax_transmission(Surface s, vec3 L, vec3 V, vec3 radiance, float thickness) {
    if (thickness > 1e29) return vec3(0.0);
    float wrap = s.data.wax.x;
    float back = max((wrap - dot(s.normal, L)) / (1.0 + wrap), 0.0);
    vec3 light = radiance * s.albedo * exp(-thickness / max(s.data.wax.y, 1e-4)) * back;
#ifdef SPLIT_LIGHTING
    split_light_diffuse += light;  // scattered light: diffuse, for an effect on it
#endif
    return light;
}
