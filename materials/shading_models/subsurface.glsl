// Subsurface scattering (the subsurface material): a Lambertian diffuse part, which the
// screen-space blur scatters under the surface (materials/subsurface), and Blinn-Phong's
// highlight, which stays sharp: the model splits its light (deferred.interfaces.shading), so the
// lighting writes the diffuse part apart. Light from behind goes through thin parts by the
// profile's transmittance at the thickness the light's shadow map gives (Jimenez et al. 2010).
// The G-buffer datum subsurface_profile holds the pixel's row of u_subsurface_profiles (texel
// 0: the profile's shape d per channel and the transmission's strength; 1 ..: the blur's taps).
#include "common/surface.glsl"

uniform sampler2D u_subsurface_profiles;

vec3 subsurface_diffuse(Surface s, vec3 L, vec3 V, vec3 radiance) {
    return radiance * max(dot(s.normal, L), 0.0) * s.albedo;
}

vec3 subsurface_specular(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    if (n_dot_l <= 0.0) return vec3(0.0);
    vec3 H = normalize(L + V);
    return radiance * (n_dot_l * s.specular_intensity *
                       pow(max(dot(s.normal, H), 0.0), s.specular_exponent));
}

vec3 subsurface(Surface s, vec3 L, vec3 V, vec3 radiance) {
    return subsurface_diffuse(s, L, V, radiance) + subsurface_specular(s, L, V, radiance);
}

vec4 subsurface_profile_of(Surface s) {
    int row = int(s.data.subsurface_profile.r * 255.0 + 0.5);
    return texelFetch(u_subsurface_profiles, ivec2(0, row), 0);
}

// T(t) = exp(-t / d) / 4 + 3 exp(-t / 3d) / 4 (materials/techniques/subsurface_profile.py),
// times the light reaching the back, taken as facing away from the front (a wrap of 0.3, as
// Jimenez et al. 2010): diffuse light, so blurred with the rest
vec3 subsurface_transmission(Surface s, vec3 L, vec3 V, vec3 radiance, float thickness) {
    vec4 profile = subsurface_profile_of(s);
    if (profile.a <= 0.0 || thickness > 1e29) return vec3(0.0);
    vec3 d = max(profile.rgb, vec3(1e-6));
    vec3 through = 0.25 * exp(-thickness / d) + 0.75 * exp(-thickness / (3.0 * d));
    vec3 light = profile.a * s.albedo * through * radiance *
                 clamp(0.3 - dot(s.normal, L), 0.0, 1.0);
#ifdef SPLIT_LIGHTING  // always, where a scene has the model
    split_light_diffuse += light;
#endif
    return light;
}
