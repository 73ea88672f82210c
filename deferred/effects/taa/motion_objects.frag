// Motion vectors of an object: this fragment's point now and in the last frame, in pixels.
#include "common/motion.glsl"

uniform vec2 u_resolution;

in vec4 v_current;
in vec4 v_previous;

out vec2 out_motion;

void main() {
    out_motion = motion_pixels(v_current, v_previous, u_resolution);
}
