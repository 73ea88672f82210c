// The equirectangular map into the first level of a cube (4 samples a texel, from the map's mip
// level whose texels are about the cube's): the source the prefiltering reads (prefilter.comp).
#include "lights/environment/directions.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba16f, binding = 0) uniform writeonly imageCube u_cube;

uniform sampler2D u_equirect;
uniform int u_size;
uniform float u_lod;

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= u_size || id.y >= u_size) return;
    vec3 total = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        vec2 offset = vec2(float(k & 1), float(k >> 1)) * 0.5 + 0.25;
        vec3 d = cube_direction(id.z, (vec2(id.xy) + offset) / float(u_size));
        total += textureLod(u_equirect, equirect_st(d), u_lod).rgb;
    }
    imageStore(u_cube, id, vec4(total * 0.25, 1.0));
}
