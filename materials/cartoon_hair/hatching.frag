// Cartoon hair hatching (Costigan 4.3.8): the hair's lit tone (its light over its albedo, the
// toon ramp's bands included) picks tonal-art-map tones whose ink darkens the composition
// (a multiply over the lit hair). Surface hatching (Praun et al., Fig. 4.20b) lays the map along
// each tube (u along the strand, `u_hatching_scale` repeats; v round it); screen hatching (Lake
// et al., Fig. 4.20a) over the screen, one map texel to `u_hatching_scale` pixels (1).
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include "materials/techniques/hatching.glsl"
#include SURFACE_FILE

uniform sampler2D u_tam;
uniform int u_tam_tones;
uniform int u_tam_gutter;
uniform float u_hatching_strength;
uniform float u_hatching_scale;
uniform bool u_hatching_screen;

out vec4 out_color;

const vec3 LUMINANCE = vec3(0.2126, 0.7152, 0.0722);

void main() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    vec3 lit = forward_lighting(s, i.position, normalize(-i.position));
    float tone = clamp(dot(lit, LUMINANCE) / max(dot(s.albedo, LUMINANCE), 1e-4), 0.0, 1.0);
    float ink = u_hatching_screen
        ? hatching_screen_ink(u_tam, u_tam_tones, u_tam_gutter, tone, gl_FragCoord.xy,
                              u_hatching_scale)
        : hatching_ink(u_tam, u_tam_tones, u_tam_gutter, tone,
                       i.uv * vec2(u_hatching_scale, 1.0));
    out_color = vec4(vec3(1.0 - u_hatching_strength * ink), 1.0);
}
