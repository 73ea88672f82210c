// Toon shading (Costigan's cartoon hair, 4.3.3-4.3.6; X-toon after Barla et al.): the light's
// intensity looked up in a ramp, a layer of u_toon_ramps that the G-buffer datum toon_ramp
// selects, and a specular band: the Blinn-Phong highlight thresholded to a hard-edged spot
// (intensity and exponent from the G-buffer; intensity 0 turns it off).
// Layers 0 .. 3 are the built-in 1D ramps over N.L from -1 to 1, filtered. The layers after
// them are X-toon ramps (deferred.materials.techniques.xtoon): x = max(N.L, 0) (4.3.3) and y a
// metric, fetched unfiltered so a quantised ramp gives exactly its tones:
//   1 depth      D = 1 - log(z / z_min) / log(z_max / z_min)  (4.3.4)
//   2 backlight  |N.V|^r                                      (4.3.5)
//   3 specular   (N.H)^c                                      (4.3.6)
// Each light looks its own intensity up; the metrics of depth and backlight are the same for
// every light, so with several lights a backlight rim is added once per light.
#include "common/surface.glsl"

uniform sampler2DArray u_toon_ramps;
uniform sampler2D u_toon_ramp_constants;  // a row per layer: metric, constant, constant, xtoon

float toon_metric(vec4 constants, Surface s, vec3 L, vec3 V) {
    int metric = int(constants.x + 0.5);
    if (metric == 1) {
        float z = max(s.view_depth, 1e-6);
        return clamp(1.0 - log(z / constants.y) / log(constants.z / constants.y), 0.0, 1.0);
    }
    if (metric == 2) {
        return pow(abs(dot(s.normal, V)), constants.y);
    }
    if (metric == 3) {
        return pow(max(dot(s.normal, normalize(L + V)), 0.0), constants.y);
    }
    return 0.0;
}

vec3 toon_ramp(Surface s, vec3 L, vec3 V, float layer) {
    ivec3 size = textureSize(u_toon_ramps, 0);
    vec4 constants = texelFetch(u_toon_ramp_constants, ivec2(int(layer), 0), 0);
    float n_dot_l = dot(s.normal, L);
    if (constants.w < 0.5) {  // a built-in 1D ramp over N.L from -1 to 1
        float u = (clamp(n_dot_l * 0.5 + 0.5, 0.0, 1.0) * float(size.x - 1) + 0.5) / float(size.x);
        return texture(u_toon_ramps, vec3(u, 0.5, layer)).rgb;
    }
    float x = clamp(n_dot_l, 0.0, 1.0);
    float y = toon_metric(constants, s, L, V);
    ivec2 texel = min(ivec2(vec2(x, y) * vec2(size.xy)), size.xy - 1);
    return texelFetch(u_toon_ramps, ivec3(texel, int(layer)), 0).rgb;
}

vec3 toon(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    vec3 diffuse = s.albedo * toon_ramp(s, L, V, floor(s.data.toon_ramp.r * 255.0 + 0.5));
    vec3 H = normalize(L + V);
    float highlight = pow(max(dot(s.normal, H), 0.0), s.specular_exponent);
    float band = n_dot_l > 0.0 ? smoothstep(0.45, 0.55, highlight) : 0.0;
    return radiance * (diffuse + vec3(s.specular_intensity * band));
}
