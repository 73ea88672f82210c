// shell_fur, deferred material phase: the layers (and fins) of Silva et al.'s fur, composited
// over the lit scene. A fragment's strands and colour come from its clumped coordinates
// (Algorithm 2, layer.glsl); its light from the light accumulation at the root under it (the
// lights shaded the base surface with kajiya_kay along the strand's chord, the G-buffer's
// strand_tangent), divided by the base albedo and multiplied by this layer's colour and the
// shadow factor gamma(h) (Eq. 6); the root's light comes from the fur_light gather, made once
// per pixel for the frame (techniques/fur_light.glsl). Each layer then shades the full-screen
// lights again along its own tangent against the chord (layer_light: a curl's light and dark
// bands); what the layers lose against the forward pipeline is the volume lights' variation
// with the tangent and the light's variation between the root and the layer.
#include "techniques/fur.glsl"
#include "techniques/accumulated_light.glsl"
#include "techniques/fur_light.glsl"
#include "materials/shell_fur/layer.glsl"
#include "materials/shell_fur/color.glsl"
#include "materials/shell_fur/debug.glsl"
#if !defined(STRAND_CHORD) || (defined(SHADOWS) && defined(OPACITY_SHADOWS) \
                               && defined(OPACITY_RECEIVER))
// The lights evaluated again in the fragment: the layers re-shade along their own tangent
// (layer_light; not the fins, lit along the chord like the base surface), and with deep opacity
// maps layers and fins shadow themselves (self_shadowed)
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "techniques/strand_tangent.glsl"
in vec3 v_position;
in vec3 v_normal;
in vec3 v_strand_tangent;  // this layer's, along the curl (fur.vert); the fins' chord
uniform float u_specular_intensity;  // K_s
uniform float u_specular_exponent;   // p_phong
#ifdef FUR_MARSCHNER
uniform float u_roughness;
#endif

Surface layer_surface(vec3 albedo, float wetness, vec3 tangent) {
    Surface s;
    s.albedo = albedo;
    s.specular_intensity = wet_specular_intensity(u_specular_intensity, wetness);
#ifdef FUR_MARSCHNER
    s.specular_exponent = wet_specular_shape(u_roughness, wetness);
#else
    s.specular_exponent = wet_specular_shape(u_specular_exponent, wetness);
#endif
    s.normal = normalize(v_normal);
    s.occlusion = 1.0;
    s.view_depth = -v_position.z;
    s.shading_model = surface_shading_model(u_surface_id);
    s.data.strand_tangent = strand_tangent_encode(tangent);
    return s;
}

#endif

#ifndef STRAND_CHORD
#define FUR_LAYER_RESHADE
in vec3 v_strand_chord;  // the strand's chord, as the base surface was lit (fur.vert)

// The light read at the root (irradiance, before gamma) re-shaded along this layer's tangent:
// the full-screen lights (ambient, directional) evaluated here along the chord (c, as the root
// was lit) and along the layer's curled tangent (t), per channel. Where c is a share of the
// root's light at most 1 it is swapped for t (irradiance - c + t); where the root saw less
// (its shadow), the root's light is scaled by t / c. The volume lights keep the chord's. The
// shadowed lights are evaluated without their transmittance, which self_shadowed applies.
vec3 layer_light(vec3 irradiance, vec3 albedo, float wetness) {
    vec3 V = normalize(-v_position);
    vec3 scale = 1.0 / max(albedo, vec3(1.0 / 255.0));
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    opacity_split = true;  // the root's light holds the shadowed lights whole (self_shadowed)
#endif
    vec3 c = evaluate_fullscreen_lights(layer_surface(albedo, wetness, v_strand_chord),
                                        v_position, V) * scale;
    vec3 t = evaluate_fullscreen_lights(layer_surface(albedo, wetness, v_strand_tangent),
                                        v_position, V) * scale;
    vec3 share = clamp(c / max(irradiance, vec3(1e-6)), 0.0, 1.0);
    return irradiance * mix(vec3(1.0), t / max(c, vec3(1e-6)), share);
}
#endif

#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
// Self-shadowing (deep opacity maps, lights/shadows.glsl): the summed light read at the root
// holds each shadowed light whole; each is evaluated again at this layer (Kajiya-Kay along the
// layer's tangent) for the transmittance-weighted share to scale (self_shadowed), gamma(h)
// staying on the rest (the forward layers' split)
#define FUR_LAYER_SELF_SHADOW

// The light read at the root (irradiance, before gamma) with the shadowed lights' share of it
// scaled by their transmittance here: each shadowed light evaluated again at this layer (e_i),
// f = sum(e_i T_i / gamma) / sum(e_i), and the share sum(e_i) / irradiance (at most 1: where the
// layer sees a light its root did not, at the terminator, the root's light is all it has)
vec3 self_shadowed(vec3 irradiance, vec3 albedo, float gamma, float wetness) {
    Surface s = layer_surface(albedo, wetness, v_strand_tangent);
    vec3 V = normalize(-v_position);
    const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);
    float total = 0.0;
    float kept = 0.0;
    opacity_split = true;
    for (int k = 0; k < u_light_count; ++k) {
        LightRecord light = fetch_light(k);
        if (light.extra.w < 0.5) continue;  // no shadow slot: gamma(h) stays
        opacity_last = 1.0;
        float e = dot(evaluate_light(light, s, v_position, V)
                      / max(albedo, vec3(1.0 / 255.0)), LUMA);
        total += e;
        kept += e * opacity_last / max(gamma, 1e-3);
    }
    float share = clamp(total / max(dot(irradiance, LUMA), 1e-6), 0.0, 1.0);
    return irradiance * mix(1.0, kept / max(total, 1e-6), share);
}
#endif

uniform float u_fur_uv_tiles;  // volume tiles per UV unit (FUR_UV_MAPPING)
uniform float u_shell_fade;    // the outermost layer fades in with the level of detail
uniform float u_shell_weight;  // slices of the fur volume per layer (shell_opacity)
uniform float u_shell_count;   // layers drawn / the most (the shell_count debug view)
uniform bool u_root_shell;     // the skin: opaque, with the roots on it

in vec2 v_uv;
in vec4 v_base_clip;
in float v_base_depth;
in float v_fur_extent;
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
    vec3 albedo = wet_albedo(fur_color_grad(layer.color_uv, layer.color_dx, layer.color_dy),
                             fur_wetness(v_uv)) * fur_shadow(v_shell_depth);
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
    float tolerance = 0.5 * v_fur_extent + 0.002 * v_base_depth;
    vec3 irradiance;
    bool base_valid = fur_light_at(pixel_of(v_base_clip), v_base_depth, tolerance, irradiance);
    vec3 own_irradiance;
    bool own_valid = !base_valid && own_fur_light(own_irradiance);
#ifdef FUR_DEBUG_SAMPLES
    out_color = vec4(own_valid || !base_valid ? 1.0 : 0.0, base_valid || own_valid ? 1.0 : 0.0,
                     0.0, 1.0);
    return;
#endif
    if (!base_valid && !own_valid) discard;  // the strand's light is unknown
    if (own_valid) irradiance = own_irradiance;
#ifdef FUR_LAYER_RESHADE
    irradiance = layer_light(irradiance, albedo / fur_shadow(v_shell_depth), fur_wetness(v_uv));
#endif
#ifdef FUR_LAYER_SELF_SHADOW
    irradiance = self_shadowed(irradiance, albedo / fur_shadow(v_shell_depth),
                               fur_shadow(v_shell_depth), fur_wetness(v_uv));
#ifdef FUR_DEBUG_OPACITY_SHADOW
    out_color = vec4(max(opacity_seen, vec3(0.0)), 1.0);
    return;
#endif
#endif
    float brightness = strand_brightness(strands);
    out_color = vec4(irradiance * strand_tint(albedo, strands) * brightness, alpha);
}
