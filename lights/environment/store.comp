// One level of the prefiltered cube from a buffer (prefilter.comp's layout): how every level
// reaches the cube, made now or read from the disk cache.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba16f, binding = 0) uniform writeonly imageCube u_cube;
layout(std430, binding = 0) readonly buffer Texels { vec4 texels[]; };

uniform int u_size;
uniform int u_first;

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= u_size || id.y >= u_size) return;
    imageStore(u_cube, id, texels[u_first + (id.z * u_size + id.y) * u_size + id.x]);
}
