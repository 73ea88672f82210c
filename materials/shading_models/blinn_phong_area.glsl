// Blinn-Phong's answer to an area light (lighting/area.glsl). Diffuse: the albedo times the
// irradiance the clipped polygon gives (exact). Specular: the lobe max(N.H, 0)^n N.L has no LTC
// fit of its own, so its shape over the polygon is GGX's of the same width (alpha =
// sqrt(2 / (n + 2)), Walter et al. 2007's Phong-Beckmann correspondence) and its total that of
// the Blinn-Phong lobe seen head on, in closed form, times GGX's fall with N.V.
#include "common/surface.glsl"
#include "lighting/area.glsl"

// The integral of max(N.H, 0)^n N.L over the hemisphere for V = N: with u = cos(theta_h),
// 8 pi times the integral of u^(n+1) (2u^2 - 1) from sqrt(1/2) to 1
float blinn_phong_lobe_total(float n) {
    float a = (1.0 - exp2(-0.5 * (n + 4.0))) * 2.0 / (n + 4.0);
    float b = (1.0 - exp2(-0.5 * (n + 2.0))) / (n + 2.0);
    return 8.0 * AREA_PI * (a - b);
}

// The highlight's share of the light: what multiplies the radiance
float blinn_phong_area_specular(Surface s, vec3 V, AreaLight a) {
    if (s.specular_intensity <= 0.0) return 0.0;
    float n = max(s.specular_exponent, 0.0);
    float roughness = sqrt(sqrt(2.0 / (n + 2.0)));  // the tables' sqrt(alpha)
    vec3 lobe = area_ggx(a, s.normal, V, roughness);
    float head_on = texture(u_ltc_amplitude, ltc_uv(roughness, 1.0)).x;
    return s.specular_intensity * blinn_phong_lobe_total(n) * lobe.x * lobe.y /
           max(head_on, 1e-4);
}

vec3 blinn_phong_area(Surface s, vec3 V, AreaLight a) {
    vec3 diffuse = s.albedo * area_irradiance(a, s.normal);
    return a.radiance * (diffuse + vec3(blinn_phong_area_specular(s, V, a)));
}
