// How wet fur looks (not in Silva et al., whose wetness only clumps and uncurls): water fills
// the gaps between the fibres and films them, so
//  - less light scatters back out of the fur: the colour darkens and saturates, albedo^(1 + d rho)
//    (WET_DARKENING = d; fully wet, a colour of 0.5 becomes 0.5^1.8 = 0.29);
//  - the film's smooth surface makes the highlight stronger and narrower: Kajiya-Kay's K_s times
//    (1 + 2 rho) (at most 1) and its exponent times (1 + 3 rho); marschner's roughness beta
//    times (1 - 0.6 rho).
// The wetness rho is the mask's alpha (clump.glsl's u_wetness_mask, which is sampled nearest for
// its clump centres) filtered bilinearly here, so the colour does not step at texel edges.

#define WET_DARKENING 0.8

uniform sampler2D u_wetness_mask;  // RGBA32F: (R, G) clump centre, B radius, A wetness

float fur_wetness(vec2 uv) {
    ivec2 size = textureSize(u_wetness_mask, 0);
    vec2 texel = uv * vec2(size) - 0.5;
    ivec2 base = ivec2(floor(texel));
    vec2 f = texel - vec2(base);
    float w00 = texelFetch(u_wetness_mask, (base + ivec2(0, 0) + size) % size, 0).a;
    float w10 = texelFetch(u_wetness_mask, (base + ivec2(1, 0) + size) % size, 0).a;
    float w01 = texelFetch(u_wetness_mask, (base + ivec2(0, 1) + size) % size, 0).a;
    float w11 = texelFetch(u_wetness_mask, (base + ivec2(1, 1) + size) % size, 0).a;
    return clamp(mix(mix(w00, w10, f.x), mix(w01, w11, f.x), f.y), 0.0, 1.0);
}

// The wetness about uv: the mean of the filtered wetness at four points 4 texels away
// diagonally (and uv itself): it rises over about eight texels toward a wet area.
float fur_wetness_near(vec2 uv) {
    vec2 step = 4.0 / vec2(textureSize(u_wetness_mask, 0));
    return (fur_wetness(uv) + fur_wetness(uv + step) + fur_wetness(uv - step)
            + fur_wetness(uv + vec2(step.x, -step.y)) + fur_wetness(uv + vec2(-step.x, step.y)))
           / 5.0;
}

vec3 wet_albedo(vec3 albedo, float wetness) {
    return pow(max(albedo, vec3(0.0)), vec3(1.0 + WET_DARKENING * wetness));
}

float wet_specular_intensity(float intensity, float wetness) {
    return min(intensity * (1.0 + 2.0 * wetness), 1.0);
}

// the specular exponent slot: Kajiya-Kay's exponent, or marschner's roughness (FUR_MARSCHNER)
float wet_specular_shape(float value, float wetness) {
#ifdef FUR_MARSCHNER
    return value * (1.0 - 0.6 * wetness);
#else
    return value * (1.0 + 3.0 * wetness);
#endif
}
