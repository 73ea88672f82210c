// A strand tangent as G-buffer data (strand_tangent, RG16F): octahedral like the normal, so a
// unit vector keeps half-float precision. The sign of T does not matter to Kajiya-Kay.
#include "gbuffer/octahedral.glsl"

vec4 strand_tangent_encode(vec3 T) {
    return vec4(octahedral_encode(normalize(T)), 0.0, 0.0);
}

vec3 strand_tangent_decode(vec4 data) {
    return octahedral_decode(data.xy);
}
