// A film over what lies behind it: its highlight (every light of the frame, with shadows)
// added, what lies behind multiplied by its tint, through dual-source blending (the pass's
// Blend("one", "src1_color")): the second output of location 0 is the destination's factor.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include SURFACE_FILE

uniform vec3 u_tint;

layout(location = 0, index = 0) out vec4 out_highlight;
layout(location = 0, index = 1) out vec4 out_tint;

void main() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    out_highlight = vec4(forward_lighting(s, i.position, normalize(-i.position)), 0.0);
    out_tint = vec4(u_tint, 1.0);
}
