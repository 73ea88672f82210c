// Revie material phase shells (2.4.4, Figure 2.20): each shell fragment takes its light from the
// light accumulation at the base-mesh point and at the outer-shell stipple sample, rejects a
// sample the G-buffer shows occluded, keeps the brighter (the scattering halo), divides out the
// albedo and re-applies albedo_base..albedo_tip over the shell depth, and fades strands with
// smoothstep against the heightfield.
#include "techniques/stipple.glsl"
#include "gbuffer/layout.glsl"

uniform sampler2D u_light_accumulation;
uniform sampler2D u_albedo_specular;
uniform sampler2D u_normal_exponent_id;
uniform sampler2D u_linear_depth;
uniform sampler2D u_heightfield;
uniform vec2 u_resolution;
uniform float u_surface_id;
uniform vec3 u_albedo_base;
uniform vec3 u_albedo_tip;
uniform float u_density;
uniform float u_strand_softness;

in vec2 v_uv;
in vec4 v_base_clip;
in vec4 v_tip_clip;
in float v_base_depth;
in float v_tip_depth;
in float v_fur_extent;
in float v_shell_depth;

out vec4 out_color;

ivec2 pixel_of(vec4 clip) {
    return ivec2(floor((clip.xy / clip.w * 0.5 + 0.5) * u_resolution));
}

// Light / albedo at `pixel` if it holds this fur within `tolerance` of `expected` depth.
bool irradiance_at(ivec2 pixel, float expected, float tolerance, out vec3 irradiance) {
    irradiance = vec3(0.0);
    if (any(lessThan(pixel, ivec2(0))) || any(greaterThanEqual(pixel, ivec2(u_resolution))))
        return false;
#ifdef FUR_OCCLUSION_TEST
    if (!same_surface(texelFetch(u_normal_exponent_id, pixel, 0).w, u_surface_id)) return false;
    if (abs(texelFetch(u_linear_depth, pixel, 0).r - expected) > tolerance) return false;
#endif
    vec3 albedo = max(texelFetch(u_albedo_specular, pixel, 0).rgb, vec3(1.0 / 255.0));
    irradiance = texelFetch(u_light_accumulation, pixel, 0).rgb / albedo;
    return true;
}

void main() {
    float height = texture(u_heightfield, v_uv * u_density).r;
    float alpha = 1.0 - smoothstep(height - u_strand_softness, height, v_shell_depth);
    if (alpha <= 0.0) discard;
    float tolerance = 0.5 * v_fur_extent + 0.002 * v_base_depth;
    vec3 base_light;
    vec3 tip_light;
    bool base_valid = irradiance_at(pixel_of(v_base_clip), v_base_depth, tolerance, base_light);
    bool tip_valid = false;
#ifdef FUR_STIPPLE
    tip_valid = irradiance_at(stipple_pixel_of(pixel_of(v_tip_clip)), v_tip_depth, tolerance,
                              tip_light);
#endif
    if (!base_valid && !tip_valid) discard;
    vec3 irradiance = base_valid && tip_valid ? max(base_light, tip_light)
                    : (base_valid ? base_light : tip_light);
    vec3 albedo = mix(u_albedo_base, u_albedo_tip, v_shell_depth);
    out_color = vec4(irradiance * albedo, alpha);
}
