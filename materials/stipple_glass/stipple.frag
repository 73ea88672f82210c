// Screen-door transparency (Revie 2.3.4, Figure 2.14): the glass into the G-buffer at the
// stipple pattern's pixels only; the pixels between keep the scene behind it.
#include "common/surface_input.glsl"
#include "gbuffer/write.glsl"
#include "materials/techniques/stipple.glsl"
#include SURFACE_FILE

void main() {
    if (!stipple_sample(ivec2(gl_FragCoord.xy))) discard;
    SurfaceInput i = surface_input();
    gbuffer_write(evaluate_surface(i), i.position, u_surface_id);
}
