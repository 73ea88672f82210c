// The image-based light (lights/environment): its record holds the view -> map rotation in the
// rows position.xyz, direction.xyz and extra.xyz, colour * intensity in color.rgb and the
// prefiltered cube's last mip level in position.w. A surface answers it through its shading
// model's environment function (shade_environment: the model's own, or its ambient answer to
// the irradiance at the normal, which is how every material without one receives it).
#include "common/lighting.glsl"

Environment environment_of(LightRecord light) {
    Environment e;
    e.to_map = transpose(mat3(light.position.xyz, light.direction.xyz, light.extra.xyz));
    e.scale = light.color.rgb;
    e.max_lod = light.position.w;
    return e;
}

vec3 environment_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    return shade_environment(s, V, environment_of(light));
}

// What the map shows in view-space direction D (scene.background = "environment")
vec3 environment_background(LightRecord light, vec3 D) {
    return environment_radiance(environment_of(light), normalize(D), 0.0);
}
