// One triangle covering the screen, from gl_VertexID 0..2 (post/fullscreen.vert, and
// lighting/fullscreen.vert instanced a light a copy). FULLSCREEN_AT_FAR puts it on the far plane
// (depth 1), where a depth test "greater" against the scene's depth passes on its surfaces only
// (deferred.lighting.volumes: surface_pass, LightTypePass): on llvmpipe the blocks of pixels
// that fail it are skipped, which an `if` in the fragment shader cannot do.

// The vertex's corner, 0..2 on each axis: the viewport's 0..1 is inside.
vec2 fullscreen_corner() {
    return vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
}

vec4 fullscreen_position(vec2 corner) {
#ifdef FULLSCREEN_AT_FAR
    return vec4(corner * 2.0 - 1.0, 1.0, 1.0);
#else
    return vec4(corner * 2.0 - 1.0, 0.0, 1.0);
#endif
}
