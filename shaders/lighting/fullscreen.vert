// A full-screen triangle per light (instanced): directional and ambient lights (on the far
// plane with FULLSCREEN_AT_FAR: common/fullscreen_triangle.glsl).
#include "common/fullscreen_triangle.glsl"

uniform int u_light_offset;

flat out int v_light_index;

void main() {
    v_light_index = u_light_offset + gl_InstanceID;
    gl_Position = fullscreen_position(fullscreen_corner());
}
