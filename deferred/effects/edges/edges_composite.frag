// Post: the edge mask drawn over the tone-mapped frame in the line colour (alpha-blended).
#include "common/color.glsl"

uniform sampler2D u_edges;
uniform vec3 u_color;     // linear RGB
uniform float u_opacity;

out vec4 out_color;

void main() {
    float edge = texelFetch(u_edges, ivec2(gl_FragCoord.xy), 0).r;
    out_color = vec4(srgb_encode(u_color), edge * u_opacity);
}
