// Toon shading (X-toon ramps, Costigan's cartoon hair): N.L from -1 to 1 looked up in a ramp
// texture whose row the G-buffer data toon_ramp selects, and a specular band: the Blinn-Phong
// highlight thresholded to a hard-edged spot (intensity and exponent from the G-buffer).
#include "common/surface.glsl"

uniform sampler2D u_toon_ramps;  // rows: ramps (deferred.materials.shading_models.toon_ramps)

vec3 toon_ramp(float n_dot_l, float row) {
    vec2 size = vec2(textureSize(u_toon_ramps, 0));
    float u = (clamp(n_dot_l * 0.5 + 0.5, 0.0, 1.0) * (size.x - 1.0) + 0.5) / size.x;
    return texture(u_toon_ramps, vec2(u, (row + 0.5) / size.y)).rgb;
}

vec3 toon(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    vec3 diffuse = s.albedo * toon_ramp(n_dot_l, floor(s.data.toon_ramp.r * 255.0 + 0.5));
    vec3 H = normalize(L + V);
    float highlight = pow(max(dot(s.normal, H), 0.0), s.specular_exponent);
    float band = n_dot_l > 0.0 ? smoothstep(0.45, 0.55, highlight) : 0.0;
    return radiance * (diffuse + vec3(s.specular_intensity * band));
}
