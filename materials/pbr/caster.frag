// The pbr material's shadow where it cuts itself out (alpha mode "mask", and "blend" taken as
// cut at alpha_cutoff): depth only, nothing where the surface is cut.
#include "common/surface_input.glsl"
#include SURFACE_FILE

void main() {
    material_surface(surface_input());
#ifdef ALPHA_BLEND
    if (pbr_alpha < u_alpha_cutoff) discard;
#endif
}
