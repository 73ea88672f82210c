// shell_fur, forward pipeline: each layer (and fin) fragment lit by every light directly, with
// Kajiya-Kay along the strand's own tangent at this layer (Silva et al. Eq. 6: C_frag =
// gamma(C_d + C_s)); colour and strands from the clumped coordinates as in the deferred layers.
// Where the scene draws deep opacity maps (OPACITY_SHADOWS), a shadowed light reaches the layer
// through the fur in front of it instead (lighting/shadows.glsl), and gamma(h) stays for the
// lights without a shadow and the ambient (its occlusion).
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include "materials/techniques/fur.glsl"
#include "materials/techniques/strand_tangent.glsl"
#include "materials/shell_fur/layer.glsl"
#include "materials/shell_fur/color.glsl"
#include "materials/shell_fur/debug.glsl"
// the surface file (which declares v_strand_tangent)
#include SURFACE_FILE

uniform float u_fur_uv_tiles;  // volume tiles per UV unit (FUR_UV_MAPPING)
uniform float u_shell_fade;
uniform float u_shell_weight;
uniform float u_shell_count;
uniform bool u_root_shell;

in float v_shell_depth;
in vec3 v_fur_position;
in vec3 v_fur_normal;
#ifdef FUR_FINS
in float v_fin_fade;
#endif
out vec4 out_color;

void main() {
    FurLayer layer = fur_layer(v_uv, v_fur_position, v_shell_depth, u_root_shell);
#ifdef FUR_UV_MAPPING
    vec2 strands = fur_sample_uv(layer.color_uv, v_shell_depth, u_fur_uv_tiles, layer.color_dx,
                                 layer.color_dy);
#else
    vec2 strands = fur_sample_grad(layer.fur_position, v_fur_normal, v_shell_depth,
                                   layer.fur_dx, layer.fur_dy);
#endif
    float wetness = fur_wetness(v_uv);
    vec3 albedo = wet_albedo(fur_color_grad(layer.color_uv, layer.color_dx, layer.color_dy),
                             wetness);
    float alpha = u_root_shell ? 1.0 : shell_opacity(strands.x, u_shell_weight) * u_shell_fade;
#ifdef FUR_FINS
    alpha *= v_fin_fade * smoothstep(0.0, 0.35, v_shell_depth);
#endif
    vec4 debug;
    if (fur_debug_view(v_uv, strands, layer.kept, u_shell_count, debug)) {
        out_color = debug;
        return;
    }
    if (!layer.kept || alpha < 0.5 / 255.0) discard;
#ifdef FUR_DEBUG_SAMPLES
    out_color = vec4(1.0);  // forward: every fragment is lit directly, no samples (white)
    return;
#endif
    Surface s;
    s.albedo = strand_tint(albedo, strands);
    s.specular_intensity = wet_specular_intensity(u_specular_intensity, wetness);
#ifdef FUR_MARSCHNER
    s.specular_exponent = wet_specular_shape(u_roughness, wetness);  // marschner's roughness
#else
    s.specular_exponent = wet_specular_shape(u_specular_exponent, wetness);
#endif
    s.normal = normalize(v_normal);
    s.occlusion = 1.0;
    s.shading_model = surface_shading_model(u_surface_id);
    s.data.strand_tangent = strand_tangent_encode(v_strand_tangent);
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    float gamma = 1.0;  // per light: the opacity maps, or gamma(h) where a light has none
    opacity_fallback = fur_shadow(v_shell_depth);
    s.occlusion = opacity_fallback;
#else
    float gamma = fur_shadow(v_shell_depth);
#endif
    vec3 light = forward_lighting(s, v_position, normalize(-v_position));
#ifdef FUR_DEBUG_OPACITY_SHADOW
    out_color = vec4(max(opacity_seen, vec3(0.0)), 1.0);
    return;
#endif
    out_color = vec4(light * gamma * strand_brightness(strands), alpha);
}
