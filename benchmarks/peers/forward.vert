// The hand-written forward loop of benchmarks/peers.py: a plain moderngl renderer, no framework.
#version 330
uniform mat4 u_model;
uniform mat4 u_view_projection;
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;

void main() {
    vec4 world = u_model * vec4(in_position, 1.0);
    v_world = world.xyz;
    v_normal = mat3(u_model) * in_normal;
    gl_Position = u_view_projection * world;
}
