// The film's shadow: its tint multiplied into the transmittance map, its depth (the nearest
// kept) beside it.
uniform vec3 u_tint;

layout(location = 0) out vec4 out_transmittance;
layout(location = 1) out float out_depth;

void main() {
    out_transmittance = vec4(u_tint, 1.0);
    out_depth = gl_FragCoord.z;
}
