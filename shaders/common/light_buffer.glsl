// All lights of the frame (deferred.lightbuffer): an SSBO on GL 4.3, a float texture on GL 3.3.
#include "common/lighting.glsl"

uniform int u_light_count;

#ifdef DEFERRED_STORAGE_BUFFERS
layout(std430, binding = 0) readonly buffer LightBuffer {
    vec4 light_data[];
};

LightRecord fetch_light(int index) {
    int base = index * 4;
    return LightRecord(light_data[base], light_data[base + 1], light_data[base + 2],
                       light_data[base + 3]);
}

vec4 fetch_light_sphere(int index) {  // position.xyz, radius: a volume light's bounds
    return light_data[index * 4 + 1];
}
#else
uniform sampler2D u_lights;  // RGBA32F, 4 texels per row, one row per light

vec4 fetch_light_sphere(int index) {
    return texelFetch(u_lights, ivec2(1, index), 0);
}

LightRecord fetch_light(int index) {
    return LightRecord(texelFetch(u_lights, ivec2(0, index), 0),
                       texelFetch(u_lights, ivec2(1, index), 0),
                       texelFetch(u_lights, ivec2(2, index), 0),
                       texelFetch(u_lights, ivec2(3, index), 0));
}
#endif
