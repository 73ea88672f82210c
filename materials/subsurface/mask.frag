// Forward: where a subsurface surface is seen (drawn with depth "equal" after every opaque
// surface): its view depth and its profile row + 1 (0: none), for the blur.
in vec3 v_position;
uniform float u_subsurface_row;

out vec4 out_surface;

void main() {
    out_surface = vec4(-v_position.z, u_subsurface_row + 1.0, 0.0, 0.0);
}
