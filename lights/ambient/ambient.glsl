// Hemisphere ambient: sky colour (color.rgb) above, ground colour (extra.rgb) below, blended by
// the normal's elevation against the up direction (direction.xyz), times the surface's ambient
// occlusion (SSAO in the deferred pipeline when the scene enables it), answered by the
// surface's shading model (diffuse albedo unless the model says otherwise).
#include "common/lighting.glsl"

vec3 ambient_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    float sky = 0.5 + 0.5 * dot(s.normal, light.direction.xyz);
    return shade_ambient(s, mix(light.extra.rgb, light.color.rgb, sky) * s.occlusion);
}
