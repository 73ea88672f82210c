// Point light: distance_falloff to zero at the radius (position.w).
#include "common/lighting.glsl"

vec3 point_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    vec3 to_light = light.position.xyz - P;
    float d = length(to_light);
    float falloff = distance_falloff(d, light.position.w);
    if (falloff <= 0.0) return vec3(0.0);
    return shade_light(s, to_light / d, V, light.color.rgb * falloff);
}
