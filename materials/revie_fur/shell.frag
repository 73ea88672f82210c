// Revie material phase shells and fins (2.4.4, Figure 2.20): each fragment takes its light from
// the light accumulation at the base-mesh point and at the outer-shell stipple sample, rejects a
// sample the G-buffer shows occluded, keeps the brighter (the scattering halo), divides out the
// albedo, and re-applies albedo_base..albedo_tip over the depth, darkened toward the roots
// (materials/techniques/fur.glsl). Its coverage comes from the mip-mapped fur volume. The first shell is
// the skin: opaque, root-coloured, over the base mesh (whose G-buffer albedo is the tip colour,
// so dividing it out of the light stays well conditioned).
//
// A base point that lands on one of this fur's stipple samples (or a pixel beside the surface)
// takes the light of the nearest neighbour holding the base surface: nothing is discarded for
// the stipple pattern, so no dot grid appears where the outer sample is off-screen or occluded.
#include "materials/techniques/stipple.glsl"
#include "materials/techniques/fur.glsl"
#include "materials/revie_fur/slab.glsl"
#include "materials/techniques/accumulated_light.glsl"
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "materials/techniques/fur_relight.glsl"
#include "materials/techniques/rim.glsl"
// material_surface (the grain normal, or marschner's strand) and u_albedo_tip
#include SURFACE_FILE
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
// Self-shadowing (deep opacity maps, lighting/shadows.glsl): the full-screen lights at the shell
// reach it through the fur in front (shell_light), the volume lights' share of the samples'
// light is scaled by their transmittance (fur_volume_self_shadowed), gamma(h) staying on the
// rest (the forward shells' split)
#define FUR_LAYER_SELF_SHADOW
#endif
#if defined(FUR_STIPPLE) && !defined(FUR_MARSCHNER)
// the stipple sample's light came through the rim-bent normal (stipple.frag), and the forward
// shells take the brighter of the grain and the rim-bent normal's light
#define FUR_RIM
uniform float u_rim_strength;
uniform float u_rim_falloff;
#endif
in vec2 v_uv;
in vec3 v_base_position;  // view space: the base point, the base sample's
in vec3 v_tip_position;   // view space: the outermost shell's point, the stipple sample's

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

// The fur's surface at a view-space point on this fragment's strand, as the lights shade it:
// the grain normal (or marschner's strand), and with rim the stipple sample's rim bending.
Surface strand_surface(vec3 position, bool rim) {
    SurfaceInput i;
    i.position = position;
    i.normal = normalize(v_normal);
    i.tangent = normalize(v_tangent);
    i.binormal = normalize(v_binormal);
    i.uv = v_uv;
    i.comb = v_comb;
    Surface s = material_surface(i);
    s.shading_model = surface_shading_model(u_surface_id);
    s.occlusion = 1.0;
    s.view_depth = -position.z;
#ifdef FUR_RIM
    if (rim) {
        s.normal = rim_bend(i.normal, s.normal, normalize(position), u_rim_strength,
                            u_rim_falloff);
    }
#endif
    return s;
}

#ifdef FUR_RIM
// The back-lit rim (Revie 2.3.2, Listing 2.3) of this fragment where the frame has volume lights
// (point, spot): every light evaluated here with the rim-bent normal, as the forward shells take
// it (the brighter of it and the grain's light).
// The stipple samples carry the rim of the outer shell only, and at a silhouette of leaning fur
// the shells showing there stand on base points whose normals are edge-on while the outer
// shell's samples in front face the viewer: lit from behind they stayed dark. Evaluated only
// where the normal bends (near silhouettes), faded in over RIM_BAND so no edge shows where it
// starts; its cost there grows with the lights.
#define RIM_BAND vec2(0.1, 0.3)
vec3 rim_light(float gamma) {
    vec3 V = normalize(-v_position);
    float weight = u_rim_strength * pow(1.0 - clamp(dot(normalize(v_normal), V), 0.0, 1.0),
                                        u_rim_falloff);
    float fade = smoothstep(RIM_BAND.x, RIM_BAND.y, weight);
    // without a volume light the samples' light, moved to the shell (fur_relight.glsl), holds
    // the full-screen lights' rim already
    if (fade <= 0.0 || u_light_count <= u_global_light_count) return vec3(0.0);
    Surface rim = strand_surface(v_position, true);
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    // as the forward shells: a shadowed light through the fur in front (the opacity maps),
    // gamma(h) on the rest; gamma divided out, the caller multiplies by it
    opacity_split = false;
    opacity_fallback = gamma;
    rim.occlusion = gamma;
#endif
    vec3 light = evaluate_fullscreen_lights(rim, v_position, V) +
                 evaluate_volume_lights(rim, v_position, V);
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    light /= max(gamma, 1e-3);
#endif
    return fade * light / max(rim.albedo, vec3(1.0 / 255.0));
}
#endif

#ifdef FUR_STIPPLE
// The outer shell's light at the strand's tip: the stipple samples around the tip's point
// (its tile's and the tiles' beside it) that hold this fur, weighted by a tent of their
// distance to it. Each tile takes its own pixel (materials/techniques/stipple.glsl), so the
// nearest sample is often a neighbouring tile's; the weights follow the point across the
// samples as the image moves, where the tile's own sample jumped from one to the next.
#ifndef TIP_RADIUS
#define TIP_RADIUS 2.0
#endif
bool tip_irradiance(vec4 clip, float expected_depth, float tolerance, out vec3 irradiance) {
    vec2 point = (clip.xy / clip.w * 0.5 + 0.5) * u_resolution;
    ivec2 pixel = ivec2(floor(point));
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int dy = -2; dy <= 2; dy += 2) {
        for (int dx = -2; dx <= 2; dx += 2) {
            ivec2 q = stipple_pixel_of(pixel + ivec2(dx, dy));
            float weight = max(0.0, 1.0 - length(vec2(q) + 0.5 - point) / TIP_RADIUS);
            if (weight <= 0.0 || !holds_fur(q, expected_depth, tolerance)) continue;
            sum += weight * irradiance_at(q);
            total += weight;
        }
    }
    irradiance = total > 0.0 ? sum / total : vec3(0.0);
    return total > 0.0;
}
#endif

#if defined(SHADOWS) || defined(FUR_FINS)
// The full-screen lights at the shell (t): where a light casts shadows, what the samples' light
// moves to; in fins, also the light of a fragment with no sample (a fin at a back-lit
// silhouette, its base and tip hidden, where TT glows)
#define FUR_SHELL_LIGHT
#endif

#ifdef FUR_SHELL_LIGHT
// The light read at the base and stipple samples (irradiance, before gamma) moved to this
// shell (materials/techniques/fur_relight.glsl) where a light casts shadows: the full-screen lights at
// each sample's point, with its surface as it was lit (c), swapped for those at the shell (t)
// with the grain normal (the base sample's) and the rim-bent one (the stipple sample's), lit
// through one shadow lookup. With deep opacity maps the shadowed ones reach the shell through
// the fur in front of it and gamma(h) stays on the rest, as in the forward shells (divided out
// here: the caller multiplies by it). `fullscreen` returns the brighter t. Without shadows the
// samples' light is kept as read: a shell's normals are its base's, the light changes between
// them with the view direction alone, and moving it brought the demo no closer to the forward
// image (benchmarks/README.md).
void shell_light(inout vec3 base_light, inout vec3 tip_light, float gamma,
                 out vec3 fullscreen) {
    Surface grain = strand_surface(v_position, false);
    vec3 inverse_albedo = 1.0 / max(grain.albedo, vec3(1.0 / 255.0));
    vec3 t_grain, t_rim;
    fur_layer_lights(grain, strand_surface(v_position, true), v_position, gamma, t_grain, t_rim);
    t_grain *= inverse_albedo;
    t_rim *= inverse_albedo;
    fullscreen = max(t_grain, t_rim);
#ifdef SHADOWS
    vec3 c = fur_sample_light(strand_surface(v_base_position, false), v_base_position)
           * inverse_albedo;
    // the forward shells take the brighter of the grain and the rim-bent normal's light, at
    // every shell: the base sample's moves to that, not to the grain's alone (its rim light
    // would be the stipple sample's, only where that is not hidden)
    base_light = fur_relit(base_light, c, fullscreen);
#ifdef FUR_STIPPLE
    c = fur_sample_light(strand_surface(v_tip_position, true), v_tip_position) * inverse_albedo;
    tip_light = fur_relit(tip_light, c, t_rim);
#endif
#endif
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
    tip_valid = tip_irradiance(v_tip_clip, v_tip_depth, tolerance, tip_light);
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
    float gamma = fur_shadow(v_shell_depth);
#ifdef FUR_SHELL_LIGHT
    vec3 fullscreen;
    shell_light(base_light, tip_light, gamma, fullscreen);
    // Neither sample (the base off-screen or hidden, the tip too: a fin at a back-lit
    // silhouette): the full-screen lights' light at the shell, or the brighter of it and the
    // light of the fur at the fragment's own pixel (another point of the fur, lit its own way:
    // it brings the volume lights)
    vec3 unsampled = own_valid ? max(irradiance_at(own), fullscreen) : fullscreen;
#else
    // a shell with no sample: the light of the fur at its own pixel, else unknown
    if (!base_valid && !tip_valid && !own_valid) discard;
    vec3 unsampled = irradiance_at(own);
#endif
    vec3 irradiance = base_valid && tip_valid ? max(base_light, tip_light)
                    : (tip_valid ? tip_light : (base_valid ? base_light : unsampled));
#ifdef FUR_LAYER_SELF_SHADOW
    irradiance = fur_volume_self_shadowed(irradiance, fullscreen,
                                          strand_surface(v_position, false), v_position,
                                          normalize(-v_position), gamma);
#ifdef FUR_DEBUG_OPACITY_SHADOW
    out_color = vec4(max(opacity_seen, vec3(0.0)), 1.0);
    return;
#endif
#endif
#ifdef FUR_RIM
    irradiance = max(irradiance, rim_light(gamma));
#endif
    float brightness = strand_brightness(strands);
    vec3 albedo = mix(u_albedo_base, u_albedo_tip, v_shell_depth) * gamma;
    out_color = vec4(irradiance * strand_tint(albedo, strands) * brightness, alpha);
}
