// Directional light: parallel rays along direction.xyz, no falloff.
#include "common/lighting.glsl"

vec3 directional_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    return shade_light(s, -light.direction.xyz, V, light.color.rgb);
}
