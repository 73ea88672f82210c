// A full-screen triangle per light (instanced): directional and ambient lights.
uniform int u_light_offset;

flat out int v_light_index;

void main() {
    v_light_index = u_light_offset + gl_InstanceID;
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
