// Stipple glass, forward technique: lit by every light and alpha-blended by opacity, which is
// what the deferred deinterlace computes from the stipple samples.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include SURFACE_FILE

uniform float u_opacity;
out vec4 out_color;

void main() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    out_color = vec4(forward_lighting(s, i.position, normalize(-i.position)), u_opacity);
}
