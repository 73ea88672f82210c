// Forward+ depth pre-pass: depth and linear view depth of the opaque surfaces, which the tile
// culling reads for its depth bounds (and which lets the lit pass shade each pixel once).
in vec3 v_position;
out float out_linear_depth;

void main() {
    out_linear_depth = -v_position.z;
}
