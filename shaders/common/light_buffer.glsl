// All lights of the frame (deferred.lighting.buffer): an RGBA32F texture, four texels per row, one
// row per light. A texture on every GL level, not a storage buffer where there is one: llvmpipe
// reads a texel faster than a storage buffer's vec4 (benchmarks/README.md, measured with the
// brute-force light loop), and the light loops read little else.
#include "common/lighting.glsl"

uniform int u_light_count;
uniform sampler2D u_lights;

vec4 fetch_light_sphere(int index) {  // position.xyz, radius: a volume light's bounds
    return texelFetch(u_lights, ivec2(1, index), 0);
}

LightRecord fetch_light(int index) {
    return LightRecord(texelFetch(u_lights, ivec2(0, index), 0),
                       texelFetch(u_lights, ivec2(1, index), 0),
                       texelFetch(u_lights, ivec2(2, index), 0),
                       texelFetch(u_lights, ivec2(3, index), 0), index);
}

// The k-th vec4 of the light's type's own data (Light.data), after the record's four: read
// through the type's generated struct (deferred.lighting.dispatch), which names each one.
vec4 light_datum(LightRecord light, int k) {
    return texelFetch(u_lights, ivec2(4 + k, light.index), 0);
}
