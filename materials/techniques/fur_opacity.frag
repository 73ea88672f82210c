// The fur in the deep opacity maps (deferred.lighting.shadows; Yuksel and Keyser 2008), drawn
// from the light by materials/techniques/fur.py's FurMaterial.draw_opacity through the fur vertex
// shader, unpushed (OPACITY_CASTER). v_position is in the light's view space there.
//   OPACITY_FIRST: the envelope's light-view depth and its negative, the smallest of each kept
//     by min blending: the fur's front, where the layers start (3.1), and its back, beyond
//     which a surface is not the fur's own (lighting/shadows.glsl);
//   otherwise: each outer shell's optical depth -ln(1 - opacity), with the opacity a shell
//     draws, times the fur's self_shadow_density k, added to every layer whose far end lies
//     behind it (3.2: additive blending), so layer i holds k x the optical depth from the front
//     to u_opacity_layers[i], and a point there keeps exp(-layer) of the light.
#include "materials/techniques/fur.glsl"

in vec3 v_position;
in vec3 v_fur_position;
in vec3 v_fur_normal;
in float v_shell_depth;

uniform float u_shell_weight;  // volume slices a shell stands for (techniques/shells.py)
#ifndef OPACITY_FIRST
uniform sampler2D u_opacity_first;
uniform vec4 u_opacity_layers;
#endif

out vec4 out_value;

void main() {
    float depth = -v_position.z;
#ifdef OPACITY_FIRST
    out_value = vec4(depth, -depth, 0.0, 0.0);
#else
    float coverage = fur_sample(v_fur_position, v_fur_normal, v_shell_depth).x;
    float opacity = min(shell_opacity(coverage, u_shell_weight), 0.999);
    float first = texelFetch(u_opacity_first, ivec2(gl_FragCoord.xy), 0).r;
    vec4 in_layer = vec4(lessThanEqual(vec4(depth - first), u_opacity_layers));
    out_value = -u_self_shadow_density * log(1.0 - opacity) * in_layer;
#endif
}
