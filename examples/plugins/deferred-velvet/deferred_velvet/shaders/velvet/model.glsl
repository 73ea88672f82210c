// Velvet: wrapped diffuse (light bleeds past the terminator, as through a pile of fibres) and a
// sheen where the surface is seen at grazing angles (fibres catch the light edge-on).
#include "common/surface.glsl"

vec3 velvet(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    float wrap = s.data.sheen.a;
    float diffuse = max((n_dot_l + wrap) / (1.0 + wrap), 0.0);
    float grazing = 1.0 - clamp(dot(s.normal, V), 0.0, 1.0);
    float sheen = s.specular_intensity * pow(grazing, s.specular_exponent) * max(n_dot_l + wrap, 0.0);
    return radiance * (s.albedo * diffuse + s.data.sheen.rgb * sheen);
}
