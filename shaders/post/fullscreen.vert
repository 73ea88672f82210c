// One triangle covering the screen; v_uv is 0..1 over the viewport.
// FULLSCREEN_AT_FAR puts it on the far plane (depth 1), where a depth test "greater" against
// the scene's depth passes on its surfaces only (deferred.light_lists.list_shading_pass, the
// volumes path's background pass).
out vec2 v_uv;

void main() {
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    v_uv = corner;
#ifdef FULLSCREEN_AT_FAR
    gl_Position = vec4(corner * 2.0 - 1.0, 1.0, 1.0);
#else
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
#endif
}
