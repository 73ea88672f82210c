// Revie material phase shells and fins (2.4.4, Figure 2.20): each fragment takes its light from
// the light accumulation at the base-mesh point and at the outer-shell stipple sample, rejects a
// sample the G-buffer shows occluded, keeps the brighter (the scattering halo), divides out the
// albedo, and re-applies albedo_base..albedo_tip over the depth, darkened toward the roots
// (techniques/fur.glsl). Its coverage comes from the mip-mapped fur volume. The first shell is
// the skin: opaque, root-coloured, over the base mesh (whose G-buffer albedo is the tip colour,
// so dividing it out of the light stays well conditioned).
//
// A base point that lands on one of this fur's stipple samples (or a pixel beside the surface)
// takes the light of the nearest neighbour holding the base surface: nothing is discarded for
// the stipple pattern, so no dot grid appears where the outer sample is off-screen or occluded.
#include "techniques/stipple.glsl"
#include "techniques/fur.glsl"
#include "materials/revie_fur/slab.glsl"
#include "techniques/accumulated_light.glsl"
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
// Self-shadowing (deep opacity maps, lights/shadows.glsl): the light read at the base and
// stipple samples holds each shadowed light whole; each is evaluated again at this shell, with
// the grain normal the base sample was lit with, for the transmittance-weighted share to scale
// (self_shadowed), gamma(h) staying on the rest (the forward shells' split). Not with the
// stipple sample's rim-bent normal too (the forward shells' brighter of the two): that doubles
// the shadow lookups; where the rim's light dominates, the share is smaller and the fur there
// darkens less.
#define FUR_LAYER_SELF_SHADOW
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
// material_surface (the grain normal) and u_albedo_tip
#include SURFACE_FILE
in vec2 v_uv;
#else
uniform vec3 u_albedo_tip;
#endif

uniform vec3 u_albedo_base;
uniform float u_shell_fade;    // the outermost shell fades in with the level of detail
uniform float u_shell_weight;  // slices of the fur volume per shell (shell_opacity)
uniform float u_shell_count;   // shells drawn / the most (the shell_count debug view)
uniform bool u_root_shell;     // the first shell: the skin, opaque, with the roots on it

in vec4 v_base_clip;
in vec4 v_tip_clip;
in float v_base_depth;
in float v_tip_depth;
in float v_fur_extent;
in float v_shell_depth;
in vec3 v_fur_position;
in vec3 v_fur_normal;
in vec4 v_comb;
in vec3 v_position;
in vec3 v_normal;
in vec3 v_tangent;
in vec3 v_binormal;
#ifdef FUR_FINS
in float v_fin_fade;
#endif

out vec4 out_color;

#ifdef FUR_LAYER_SELF_SHADOW
// The light read from the samples (irradiance, before gamma) with the shadowed lights' share of
// it scaled by their transmittance here: each shadowed light evaluated again at this shell
// (e_i), f = sum(e_i T_i / gamma) / sum(e_i), and the share sum(e_i) / irradiance, at most what
// the ambient (FUR_AMBIENT_LIGHT, evaluated here too) leaves of it: where the shell sees more of
// a light than its samples did, past their terminator, the ambient in their light is kept, so
// the fur there falls to its ambient light and turns no black
vec3 self_shadowed(vec3 irradiance, float gamma) {
    SurfaceInput i;
    i.position = v_position;
    i.normal = normalize(v_normal);
    i.tangent = normalize(v_tangent);
    i.binormal = normalize(v_binormal);
    i.uv = v_uv;
    i.comb = v_comb;
    Surface s = material_surface(i);
    s.shading_model = surface_shading_model(u_surface_id);
    s.occlusion = 1.0;
    vec3 V = normalize(-v_position);
    vec3 inverse_albedo = 1.0 / max(s.albedo, vec3(1.0 / 255.0));
    const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);
    float total = 0.0;
    float kept = 0.0;
    float ambient = 0.0;
    opacity_split = true;
    for (int k = 0; k < u_light_count; ++k) {
        LightRecord light = fetch_light(k);
#ifdef FUR_AMBIENT_LIGHT
        if (int(light.color.w + 0.5) == FUR_AMBIENT_LIGHT) {
            // lights/ambient.glsl's hemisphere, inline: through evaluate_light's dispatch
            // llvmpipe runs every light type's code, shadow lookups included
            float sky = 0.5 + 0.5 * dot(s.normal, light.direction.xyz);
            vec3 hemisphere = mix(light.extra.rgb, light.color.rgb, sky);
            ambient += dot(shade_ambient(s, hemisphere) * inverse_albedo, LUMA);
            continue;
        }
#endif
        if (light.extra.w < 0.5) continue;  // no shadow slot: gamma(h) stays
        opacity_last = 1.0;
        vec3 lit = evaluate_light(light, s, v_position, V);

        float e = dot(lit * inverse_albedo, LUMA);
        total += e;
        kept += e * opacity_last / max(gamma, 1e-3);
    }
    float read = max(dot(irradiance, LUMA), 1e-6);
    float share = clamp(total / read, 0.0, max(1.0 - ambient / read, 0.0));
    return irradiance * mix(1.0, kept / max(total, 1e-6), share);
}
#endif

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
    float tolerance = 0.5 * v_fur_extent + 0.002 * v_base_depth;
    vec3 base_light;
    vec3 tip_light = vec3(0.0);
    bool base_valid = base_irradiance(pixel_of(v_base_clip), v_base_depth, tolerance, base_light);
    bool tip_valid = false;
#ifdef FUR_STIPPLE
    ivec2 tip = stipple_pixel_in(pixel_of(v_tip_clip));
    tip_valid = holds_fur(tip, v_tip_depth, tolerance);
    if (tip_valid) tip_light = irradiance_at(tip);
#endif
    // Both hidden (the base off-screen, the tip occluded): the light of the fur under this
    // fragment itself, if its pixel holds this fur, rather than a hole onto the dark skin.
    ivec2 own = ivec2(gl_FragCoord.xy);
    bool own_valid = !base_valid && !tip_valid && own_pixel_holds_fur();
#ifdef FUR_DEBUG_SAMPLES
    bool none = !base_valid && !tip_valid && !own_valid;
    out_color = vec4(none || own_valid ? 1.0 : 0.0, base_valid || own_valid ? 1.0 : 0.0,
                     tip_valid ? 1.0 : 0.0, 1.0);  // own pixel: yellow
    return;
#endif
    if (!base_valid && !tip_valid && !own_valid) discard;  // the strand's light is unknown
    vec3 irradiance = base_valid && tip_valid ? max(base_light, tip_light)
                    : (base_valid ? base_light : (tip_valid ? tip_light : irradiance_at(own)));
#ifdef FUR_LAYER_SELF_SHADOW
    irradiance = self_shadowed(irradiance, fur_shadow(v_shell_depth));
#ifdef FUR_DEBUG_OPACITY_SHADOW
    out_color = vec4(max(opacity_seen, vec3(0.0)), 1.0);
    return;
#endif
#endif
    float brightness = strand_brightness(strands);
    vec3 albedo = mix(u_albedo_base, u_albedo_tip, v_shell_depth) * fur_shadow(v_shell_depth);
    out_color = vec4(irradiance * strand_tint(albedo, strands) * brightness, alpha);
}
