// Forward pipeline: a material's surface lit by every light of the frame in one pass.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include SURFACE_FILE

out vec4 out_color;

void main() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    out_color = vec4(forward_lighting(s, i.position, normalize(-i.position)), 1.0);
}
