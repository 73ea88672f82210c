// Directional light: parallel rays along direction.xyz, no falloff; shadowed through its
// cascades where it casts shadows (lights/shadows.glsl).
#include "common/lighting.glsl"
#include "lights/shadows.glsl"

vec3 directional_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    vec3 L = -light.direction.xyz;
    return shade_light(s, L, V, light.color.rgb * light_shadow_cascades(light, P, s.normal, L));
}
