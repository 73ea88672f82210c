// Forward+ depth pre-pass: depth and linear view depth of the opaque surfaces, which the tile
// culling reads for its depth bounds (and which lets the lit pass shade each pixel once). A
// surface that cuts itself out (SURFACE_DISCARDS: an alpha mask) is evaluated, so that it
// leaves no depth where it is cut.
#ifdef SURFACE_DISCARDS
#include "common/surface_input.glsl"
#include SURFACE_FILE
#else
in vec3 v_position;
#endif
out float out_linear_depth;

void main() {
#ifdef SURFACE_DISCARDS
    material_surface(surface_input());
#endif
    out_linear_depth = -v_position.z;
}
