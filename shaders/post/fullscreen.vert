// One triangle covering the screen; v_uv is 0..1 over the viewport (on the far plane with
// FULLSCREEN_AT_FAR: common/fullscreen_triangle.glsl).
#include "common/fullscreen_triangle.glsl"

out vec2 v_uv;

void main() {
    vec2 corner = fullscreen_corner();
    v_uv = corner;
    gl_Position = fullscreen_position(corner);
}
