// Light records and the reflectance model shared by the deferred and forward pipelines.
#include "common/surface.glsl"

// One light, four vec4s in view space (deferred.light.Light.record):
//   color     rgb = colour * intensity, w = light type id
//   position  xyz = position, w = radius (volume lights)
//   direction xyz = direction the light travels, w = type-specific (spot: cos outer angle)
//   extra     type-specific (spot: x = cos inner angle; ambient: rgb = ground colour)
struct LightRecord {
    vec4 color;
    vec4 position;
    vec4 direction;
    vec4 extra;
};

// Blinn-Phong with the G-buffer's quantities (albedo, specular intensity and exponent).
vec3 blinn_phong(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    if (n_dot_l <= 0.0) return vec3(0.0);
    vec3 H = normalize(L + V);
    float specular = s.specular_intensity * pow(max(dot(s.normal, H), 0.0), s.specular_exponent);
    return radiance * n_dot_l * (s.albedo + vec3(specular));
}

// Inverse-square falloff windowed to reach exactly 0 at the radius:
//   (clamp(1 - (d/r)^4, 0, 1))^2 / (d^2 + 1)
float distance_falloff(float d, float radius) {
    float ratio = d / radius;
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    return window * window / (d * d + 1.0);
}

// Spot cone: 1 inside the inner angle, 0 outside the outer one, smoothstep between.
float cone_falloff(float cos_angle, float cos_outer, float cos_inner) {
    return smoothstep(cos_outer, cos_inner, cos_angle);
}
