// The glass's shadow (deferred.lighting.shadows.transmittance): its transmittance at normal
// incidence, (1 - opacity) (1 - F0) colour, multiplied into the transmittance map, and its
// depth along the light, the nearest kept.
uniform vec3 u_color;
uniform float u_glass_opacity;

layout(location = 0) out vec4 out_transmittance;
layout(location = 1) out float out_depth;

const float GLASS_F0 = 0.04;

void main() {
    out_transmittance = vec4((1.0 - u_glass_opacity) * (1.0 - GLASS_F0) * u_color, 1.0);
    out_depth = gl_FragCoord.z;
}
