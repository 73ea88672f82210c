// Light records and the shading-model interface shared by the deferred and forward pipelines.
#include "common/surface.glsl"
#include "lighting/environment.glsl"

// One light, four vec4s in view space (deferred.interfaces.light.Light.record):
//   color     rgb = colour * intensity, w = light type id
//   position  xyz = position, w = radius (volume lights)
//   direction xyz = direction the light travels, w = type-specific (spot: cos outer angle)
//   extra     type-specific (spot: x = cos inner angle; ambient: rgb = ground colour); w = the
//             shadow slot, written by the framework (lighting/shadows.glsl; 0: no shadow)
// and the light's row in the light buffer, where a type with data of its own (Light.data) reads
// it: through <glsl_function>_data(light), a struct generated with the type's dispatch.
struct LightRecord {
    vec4 color;
    vec4 position;
    vec4 direction;
    vec4 extra;
    int index;
};

// The surface's shading model answers a light (generated dispatch, deferred.interfaces.shading):
// L unit toward the light, V unit toward the viewer, radiance arriving at the point.
vec3 shade_light(Surface s, vec3 L, vec3 V, vec3 radiance);
// ... and ambient irradiance (default: albedo * irradiance).
vec3 shade_ambient(Surface s, vec3 irradiance);
// ... and the image-based light (default: shade_ambient of its irradiance at the normal).
vec3 shade_environment(Surface s, vec3 V, Environment e);

#ifdef SPLIT_LIGHTING
// the diffuse part of the light answered so far at this point by a model that splits it
// (deferred.interfaces.shading): the lighting passes write it beside the whole
vec3 split_light_diffuse = vec3(0.0);
#endif
#ifdef SURFACE_TRANSMISSION
// light through the surface from a light behind it (a model's transmission function; 0 for the
// others): radiance unshadowed, thickness from the light's shadow maps
vec3 shade_transmission(Surface s, vec3 L, vec3 V, vec3 radiance, float thickness);
#endif

// Inverse-square falloff windowed to reach exactly 0 at the radius:
//   (clamp(1 - (d/r)^4, 0, 1))^2 / (d^2 + 1)
float distance_falloff(float d, float radius) {
    float ratio = d / radius;
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    return window * window / (d * d + 1.0);
}

// Spot cone: 1 inside the inner angle, 0 outside the outer one, smoothstep between.
float cone_falloff(float cos_angle, float cos_outer, float cos_inner) {
    return smoothstep(cos_outer, cos_inner, cos_angle);
}
