// Cartoon hair hatching (Costigan 4.3.8): the hair's lit tone (its light over its albedo, the
// toon ramp's bands included) picks tonal-art-map tones whose ink darkens the composition
// (a multiply over the lit hair), drawn as pen strokes (hatching_pen_ink: one mip level, the
// ink thresholded to a crisp edge). Surface hatching (Praun et al., Fig. 4.20b) lays the map
// along each tube (u along the strand, `u_hatching_scale` repeats; v round it); screen
// hatching (Lake et al., Fig. 4.20a) over the screen, one map texel a pixel, so its strokes are
// the map's stroke width in pixels.
//
// Round the tube v runs 0 .. (sides - 1) / sides over the vertices and back to 0: the last
// facet interpolates the whole tile backwards. The tubes also carry fract(v + 1/2) (comb.w);
// each fragment takes whichever of the two changes less across the pixel (Tarini's seamless
// cylindrical mapping), so no facet squeezes the map.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include "materials/techniques/hatching.glsl"
#include SURFACE_FILE

uniform sampler2D u_tam;
uniform int u_tam_tones;
uniform int u_tam_gutter;
uniform int u_tam_mips;
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
    float around = i.uv.y;
    float shifted = i.comb.w - 0.5;  // around, or around - 1 past the middle
    bool seam = fwidth(shifted) < fwidth(around);
    vec2 surface_uv = vec2(i.uv.x * u_hatching_scale, seam ? shifted : around);
    vec2 surface_dx = vec2(dFdx(i.uv.x), seam ? dFdx(shifted) : dFdx(around));
    vec2 surface_dy = vec2(dFdy(i.uv.x), seam ? dFdy(shifted) : dFdy(around));
    surface_dx.x *= u_hatching_scale;
    surface_dy.x *= u_hatching_scale;
    float texel = 1.0 / float(textureSize(u_tam, 0).y - 2 * u_tam_gutter);
    vec2 uv = u_hatching_screen ? gl_FragCoord.xy * texel : surface_uv;
    vec2 duv_dx = u_hatching_screen ? vec2(texel, 0.0) : surface_dx;
    vec2 duv_dy = u_hatching_screen ? vec2(0.0, texel) : surface_dy;
    float ink = hatching_pen_ink(u_tam, u_tam_tones, u_tam_gutter, u_tam_mips, tone, uv,
                                 duv_dx, duv_dy);
    out_color = vec4(vec3(1.0 - u_hatching_strength * ink), 1.0);
}
