// shell_fur, deferred material phase: the layers (and fins) of Silva et al.'s fur, composited
// over the lit scene. A fragment's strands and colour come from its clumped coordinates
// (Algorithm 2, layer.glsl); its light from the light accumulation at the root under it (the
// lights shaded the base surface with kajiya_kay along the strand's chord, the G-buffer's
// strand_tangent), divided by the base albedo and multiplied by this layer's colour and the
// shadow factor gamma(h) (Eq. 6); the root's light comes from the fur_light gather, made once
// per pixel for the frame (materials/techniques/fur_light.glsl). The full-screen lights' share of it is
// then moved to the layer (layer_light, materials/techniques/fur_relight.glsl): a curl's light and dark
// bands, a strand standing out of its skin's shadow. What the layers lose against the forward
// pipeline is the volume lights' variation with the tangent and between the root and the layer.
#include "materials/techniques/fur.glsl"
#include "materials/techniques/accumulated_light.glsl"
#include "materials/techniques/fur_light.glsl"
#include "materials/shell_fur/layer.glsl"
#include "materials/shell_fur/color.glsl"
#include "materials/shell_fur/debug.glsl"
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "materials/techniques/fur_relight.glsl"
#include "materials/techniques/strand_tangent.glsl"
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
// Self-shadowing (deep opacity maps, lighting/shadows.glsl): the full-screen lights at the layer
// reach it through the fur in front (layer_light), the volume lights' share of the root's
// light is scaled by their transmittance (fur_volume_self_shadowed), gamma(h) staying on the
// rest (the forward layers' split)
#define FUR_LAYER_SELF_SHADOW
#endif
in vec3 v_position;
in vec3 v_normal;
in vec3 v_strand_tangent;  // this layer's, along the curl (fur.vert); the fins' chord
in vec3 v_base_position;   // the root, view space
#ifndef STRAND_CHORD
in vec3 v_strand_chord;    // the strand's chord, as the base surface was lit (fur.vert)
#endif
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

// The light read at the root (irradiance, before gamma) moved to this layer: the full-screen
// lights at the root along the strand's chord, as the base surface was lit (c), swapped for
// those at the layer along its own tangent (t; the fins': the chord), per channel
// (fur_relit). With deep opacity maps the shadowed ones reach the layer through the fur in
// front of it and gamma(h) stays on the rest, as in the forward layers (divided out here: the
// caller multiplies by it); `fullscreen` returns t.
vec3 layer_light(vec3 irradiance, vec3 albedo, float wetness, float gamma,
                 out vec3 fullscreen) {
    vec3 inverse_albedo = 1.0 / max(albedo, vec3(1.0 / 255.0));
    Surface s = layer_surface(albedo, wetness, v_strand_tangent);
    vec3 unused;
    fur_layer_lights(s, s, v_position, gamma, fullscreen, unused);
    fullscreen *= inverse_albedo;
#ifdef STRAND_CHORD
    Surface root = s;
#else
    Surface root = layer_surface(albedo, wetness, v_strand_chord);
#endif
    root.view_depth = -v_base_position.z;
    vec3 c = fur_sample_light(root, v_base_position) * inverse_albedo;
    return fur_relit(irradiance, c, fullscreen);
}

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
    float wetness = fur_wetness(v_uv);
    float gamma = fur_shadow(v_shell_depth);
    vec3 colour = wet_albedo(fur_color_grad(layer.color_uv, layer.color_dx, layer.color_dy),
                             wetness);
    vec3 albedo = colour * gamma;
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
    vec3 fullscreen;
    irradiance = layer_light(irradiance, colour, wetness, gamma, fullscreen);
    // No root sample (off-screen or hidden: a fin at a back-lit silhouette): the full-screen
    // lights' light at the layer, or the brighter of it and the light of the fur at the
    // fragment's own pixel (another point of the fur, lit its own way: it brings the volume
    // lights)
    if (!base_valid) irradiance = own_valid ? max(own_irradiance, fullscreen) : fullscreen;
#ifdef FUR_LAYER_SELF_SHADOW
    irradiance = fur_volume_self_shadowed(irradiance, fullscreen,
                                          layer_surface(colour, wetness, v_strand_tangent),
                                          v_position, normalize(-v_position), gamma);
#ifdef FUR_DEBUG_OPACITY_SHADOW
    out_color = vec4(max(opacity_seen, vec3(0.0)), 1.0);
    return;
#endif
#endif
    float brightness = strand_brightness(strands);
    out_color = vec4(irradiance * strand_tint(albedo, strands) * brightness, alpha);
}
