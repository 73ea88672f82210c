// Rim light: parallel light along direction.xyz, weighted by (1 - N.V)^power (direction.w),
// answered by the surface's shading model like any light.
#include "common/lighting.glsl"

vec3 rim_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    float rim = pow(1.0 - clamp(dot(s.normal, V), 0.0, 1.0), light.direction.w);
    return shade_light(s, -light.direction.xyz, V, light.color.rgb * rim);
}
