// Spot light: a point light times cone_falloff around direction.xyz
// (direction.w = cos outer angle, extra.x = cos inner angle); shadowed through one perspective
// map where it casts shadows (lighting/shadows.glsl).
#include "common/lighting.glsl"
#include "lighting/shadows.glsl"

vec3 spot_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    vec3 to_light = light.position.xyz - P;
    float d = length(to_light);
    vec3 L = to_light / d;
    float cone = cone_falloff(dot(-L, light.direction.xyz), light.direction.w, light.extra.x);
    float falloff = distance_falloff(d, light.position.w) * cone;
    if (falloff <= 0.0) return vec3(0.0);
    vec3 lit = light_shadow_perspective(light, P, s.normal, L);  // coloured through glass
    vec3 shaded = shade_light(s, L, V, light.color.rgb * (falloff * lit));
#ifdef SURFACE_TRANSMISSION
    shaded += shade_transmission(s, L, V, light.color.rgb * falloff,
                                 light_thickness_perspective(light, P, s.normal));
#endif
    return shaded;
}
