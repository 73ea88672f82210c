// Revie fur, forward technique (2.4: "a separate technique ... in a forward-shaded fashion"):
// each shell or fin fragment is lit directly by every light, with the grain normal and, as the
// deferred stipple sample does, with the rim-bent normal; the brighter wins. Coverage, albedo
// over the depth and self-shadowing are those of the deferred shells; where the scene draws deep
// opacity maps (OPACITY_SHADOWS), a shadowed light reaches the shell through the fur in front of
// it (lighting/shadows.glsl) and gamma(h) stays for the lights without a shadow and the ambient.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include "materials/techniques/rim.glsl"
#include "materials/techniques/fur.glsl"
#include "materials/revie_fur/slab.glsl"
#include SURFACE_FILE

uniform vec3 u_albedo_base;
uniform float u_rim_strength;
uniform float u_rim_falloff;
uniform float u_shell_fade;
uniform float u_shell_weight;  // slices of the fur volume per shell (shell_opacity)
uniform float u_shell_count;   // shells drawn / the most (the shell_count debug view)
uniform bool u_root_shell;  // the first shell: the skin, opaque, with the strands' roots on it

in float v_shell_depth;
in vec3 v_fur_position;
in vec3 v_fur_normal;
#ifdef FUR_FINS
in float v_fin_fade;
#endif
out vec4 out_color;

void main() {
#ifdef FUR_FINS
    vec2 strands = fur_sample(v_fur_position, v_fur_normal, v_shell_depth);
#else
    vec3 comb_packed = v_comb.xyz * 2.0 - 1.0;
    vec2 strands = u_root_shell
        ? fur_sample(v_fur_position, v_fur_normal, v_shell_depth)
        : fur_sample_slab(v_fur_position, v_fur_normal, v_shell_depth, u_shell_weight / 16.0,
                          v_position, v_tangent * comb_packed.x + v_binormal * comb_packed.y,
                          v_comb.a);
#endif
    float alpha = u_root_shell ? 1.0 : shell_opacity(strands.x, u_shell_weight) * u_shell_fade;
#ifdef FUR_FINS
    // Fins show the strands above the shells' rims; their roots sit inside the fur in front
    // and, drawn edge-on and dark, would read as spikes.
    alpha *= v_fin_fade * smoothstep(0.0, 0.35, v_shell_depth);
#endif
#if defined(FUR_DEBUG_COMB)
    // the view-space comb x lean, packed: independent of the UVs' tangent frames
    vec3 c = v_comb.xyz * 2.0 - 1.0;
    out_color = vec4((v_tangent * c.x + v_binormal * c.y + v_normal * c.z) * 0.5 + 0.5, 1.0);
    return;
#elif defined(FUR_DEBUG_SHELL_COUNT)
    out_color = vec4(mix(vec3(0.1, 0.2, 1.0), vec3(1.0, 0.15, 0.1), u_shell_count), 1.0);
    return;
#endif
#ifdef FUR_DEBUG_SINGLE_SHELL
    alpha = strands.x > 0.02 ? 1.0 : 0.0;  // the cut through the strands, opaque
#endif
    if (alpha < 0.5 / 255.0) discard;
#ifdef FUR_DEBUG_SAMPLES
    out_color = vec4(1.0);  // forward: every fragment is lit directly, no samples (white)
    return;
#endif
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    vec3 V = normalize(-i.position);
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    float gamma = 1.0;  // per light: the opacity maps, or gamma(h) where a light has none
    opacity_fallback = fur_shadow(v_shell_depth);
    s.occlusion *= opacity_fallback;
#else
    float gamma = fur_shadow(v_shell_depth);
#endif
    vec3 light = forward_lighting(s, i.position, V);
#ifdef FUR_DEBUG_OPACITY_SHADOW
    out_color = vec4(max(opacity_seen, vec3(0.0)), 1.0);
    return;
#endif
#if defined(FUR_STIPPLE) && !defined(FUR_MARSCHNER)  // marschner: TT lights the rim
    Surface rim = s;
    rim.normal = rim_bend(i.normal, s.normal, -V, u_rim_strength, u_rim_falloff);
    light = max(light, forward_lighting(rim, i.position, V));
#endif
    vec3 irradiance = light / max(s.albedo, vec3(1.0 / 255.0));
    float brightness = strand_brightness(strands);
    vec3 albedo = mix(u_albedo_base, u_albedo_tip, v_shell_depth) * gamma;
    out_color = vec4(irradiance * strand_tint(albedo, strands) * brightness, alpha);
}
