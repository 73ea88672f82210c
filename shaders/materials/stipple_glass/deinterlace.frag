// Material phase of stipple glass: deinterlace the tile's glass sample and the scene samples
// around it, and blend them by opacity over every pixel the glass covers.
#include "techniques/stipple.glsl"

uniform sampler2D u_light_accumulation;
uniform sampler2D u_normal_exponent_id;
uniform sampler2D u_linear_depth;
uniform vec2 u_resolution;
uniform float u_material_id;
uniform float u_opacity;

in vec3 v_position;
out vec4 out_color;

vec4 light_at(ivec2 pixel) {
    return texelFetch(u_light_accumulation, clamp(pixel, ivec2(0), ivec2(u_resolution) - 1), 0);
}

void main() {
    ivec2 glass = stipple_pixel_of(ivec2(gl_FragCoord.xy));
    // The tile's sample must be this glass (an edge tile may hold something else).
    float depth = texelFetch(u_linear_depth, glass, 0).r;
    if (abs(texelFetch(u_normal_exponent_id, glass, 0).w - u_material_id) > 0.5) discard;
    if (abs(depth + v_position.z) > 0.02 * depth + 1e-3) discard;
#if STIPPLE_PATTERN == 2
    vec4 behind = 0.5 * (light_at(glass + ivec2(1, 0)) + light_at(glass - ivec2(1, 0)));
#else
    vec4 behind = (light_at(glass + ivec2(1, 0)) + light_at(glass + ivec2(0, 1))
                   + light_at(glass + ivec2(1, 1))) / 3.0;
#endif
    out_color = vec4(mix(behind.rgb, light_at(glass).rgb, u_opacity), 1.0);
}
