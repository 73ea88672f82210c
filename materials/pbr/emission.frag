// The pbr material's emission, added over its lit pixels in the deferred pipeline (the
// G-buffer has no channel for it): the surface drawn again where its depth is, added.
#include "common/surface_input.glsl"
#include SURFACE_FILE

out vec4 out_color;

void main() {
    SurfaceInput i = surface_input();
    material_surface(i);  // its cut-outs (alpha mode "mask") and pbr_emitted
    out_color = vec4(pbr_emitted, 0.0);
}
