// Forward: the subsurface surface lit by every light, its diffuse part written apart for the
// blur (the scene splits its light: deferred.interfaces.shading).
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include SURFACE_FILE

layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_diffuse;

void main() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    out_color = vec4(forward_lighting(s, i.position, normalize(-i.position)), 1.0);
    out_diffuse = vec4(split_light_diffuse, 1.0);
}
