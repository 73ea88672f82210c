// Stipple obliteration (Revie 2.4.4, Figure 2.19): drawn with the stippled mesh; where this
// mesh's stipple sample sits, the neighbouring pixel's composition (a snapshot taken after the
// materials' own opaque passes) and depth replace it, leaving the scene the stipple covered.
#include "techniques/stipple.glsl"
#include "gbuffer/layout.glsl"

uniform sampler2D u_composite_snapshot;
uniform sampler2D u_linear_depth;
uniform sampler2D u_normal_exponent_id;
uniform float u_surface_id;
uniform vec2 u_resolution;
uniform mat4 u_projection;

in vec3 v_position;
out vec4 out_color;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    if (!stipple_sample(pixel)) discard;
    // Ours only if the G-buffer holds this very surface: same material, same depth.
    float depth = texelFetch(u_linear_depth, pixel, 0).r;
    if (!same_surface(texelFetch(u_normal_exponent_id, pixel, 0).w, u_surface_id)) discard;
    if (abs(depth + v_position.z) > 1e-3 * depth + 1e-5) discard;
    ivec2 neighbour = stipple_neighbour(pixel, ivec2(u_resolution));
    out_color = texelFetch(u_composite_snapshot, neighbour, 0);
    gl_FragDepth = window_depth(texelFetch(u_linear_depth, neighbour, 0).r, u_projection);
}
