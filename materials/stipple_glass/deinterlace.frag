// Material phase of stipple glass: every pixel the glass covers takes the light of its tile's
// glass sample, blended by opacity over the composition buffer - which by now holds the scene
// behind (the glass's own stipple samples were obliterated first, and volumes such as fur
// shells behind the glass were composited before it).
#include "materials/techniques/stipple.glsl"
#include "gbuffer/layout.glsl"

uniform sampler2D u_light_accumulation;
uniform sampler2D u_normal_exponent_id;
uniform sampler2D u_linear_depth;
uniform vec2 u_resolution;
uniform float u_surface_id;
uniform float u_opacity;

in vec3 v_position;
out vec4 out_color;

void main() {
    ivec2 glass = min(stipple_pixel_in(ivec2(gl_FragCoord.xy)), ivec2(u_resolution) - 1);
    // The tile's sample must be this glass (an edge tile may hold something else).
    float depth = texelFetch(u_linear_depth, glass, 0).r;
    if (!same_surface(texelFetch(u_normal_exponent_id, glass, 0).w, u_surface_id)) discard;
    if (abs(depth + v_position.z) > 0.02 * depth + 1e-3) discard;
    out_color = vec4(texelFetch(u_light_accumulation, glass, 0).rgb, u_opacity);
}
