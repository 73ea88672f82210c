// A full-screen triangle per light (instanced): directional and ambient lights. On the far
// plane with FULLSCREEN_AT_FAR, as in post/fullscreen.vert: a depth test "greater" then keeps
// it to the scene's surfaces (deferred.light.LightTypePass).
uniform int u_light_offset;

flat out int v_light_index;

void main() {
    v_light_index = u_light_offset + gl_InstanceID;
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
#ifdef FULLSCREEN_AT_FAR
    gl_Position = vec4(corner * 2.0 - 1.0, 1.0, 1.0);
#else
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
#endif
}
