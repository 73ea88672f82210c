// Directional light: parallel rays along direction.xyz, no falloff; shadowed through its
// cascades where it casts shadows (lighting/shadows.glsl).
#include "common/lighting.glsl"
#include "lighting/shadows.glsl"

// The radiance arriving at P on a surface of normal N (its shadow lookups' normal offset), and
// L, unit toward the light: what directional_light shades, for a caller that shades more than
// one surface at P with one shadow lookup (materials/techniques/fur_relight.glsl).
vec3 directional_radiance(LightRecord light, vec3 P, vec3 N, out vec3 L) {
    L = -light.direction.xyz;
    return light.color.rgb * light_shadow_cascades(light, P, N, L);
}

vec3 directional_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    vec3 L;
    vec3 radiance = directional_radiance(light, P, s.normal, L);
#ifdef SURFACE_TRANSMISSION
    return shade_light(s, L, V, radiance) +
           shade_transmission(s, L, V, light.color.rgb,
                              light_thickness_cascades(light, P, s.normal));
#else
    return shade_light(s, L, V, radiance);
#endif
}
