// A fur shell's depth from a light (materials/techniques/fur.py, FurMaterial.draw_shadow): the
// root shell is opaque skin; an outer shell is kept where an ordered dither falls under its
// opacity (the fur volume's coverage at its height, as the shell draws it), so the filtered
// shadow darkens with the fur's density. With FUR_FINS the same for a fin (fins.geom).
#include "materials/techniques/fur.glsl"

in vec3 v_fur_position;
in vec3 v_fur_normal;
in float v_shell_depth;

#ifdef FUR_FINS
in float v_fin_fade;  // fins.geom: the fin fading in toward the light's silhouette
#endif

uniform bool u_root_shell;
uniform float u_shell_weight;  // volume slices a shell stands for (techniques/shells.py)

void main() {
    if (u_root_shell) return;
    float coverage = fur_sample(v_fur_position, v_fur_normal, v_shell_depth).x;
    // interleaved gradient noise (Jimenez 2014): a threshold per texel in [0, 1)
    float dither = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
    float opacity = shell_opacity(coverage, u_shell_weight);
#ifdef FUR_FINS
    opacity *= v_fin_fade * smoothstep(0.0, 0.35, v_shell_depth);  // as the fins draw (shell.frag)
#endif
    if (opacity <= dither) discard;
}
