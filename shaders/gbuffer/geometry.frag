// Geometry phase: a material's surface into the G-buffer (the material is SURFACE_FILE).
#include "common/surface_input.glsl"
#include "gbuffer/write.glsl"
#include SURFACE_FILE

void main() {
    SurfaceInput i = surface_input();
    gbuffer_write(evaluate_surface(i), i.position, u_surface_id);
}
