// Point light: distance_falloff to zero at the radius (position.w); shadowed through six cube
// tiles where it casts shadows (lighting/shadows.glsl).
#include "common/lighting.glsl"
#include "lighting/shadows.glsl"

vec3 point_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    vec3 to_light = light.position.xyz - P;
    float d = length(to_light);
    float falloff = distance_falloff(d, light.position.w);
    if (falloff <= 0.0) return vec3(0.0);
    vec3 L = to_light / d;
    vec3 lit = light_shadow_cube(light, P, s.normal, L);  // coloured through glass
    vec3 shaded = shade_light(s, L, V, light.color.rgb * (falloff * lit));
#ifdef SURFACE_TRANSMISSION
    shaded += shade_transmission(s, L, V, light.color.rgb * falloff,
                                 light_thickness_cube(light, P, s.normal));
#endif
    return shaded;
}
