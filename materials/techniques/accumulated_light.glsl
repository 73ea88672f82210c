// Light for fur layers from the light accumulation (Revie 2.4.4, Listing 2.2): a shell or fin
// fragment takes the light of the base-mesh point under it, read back from the light
// accumulation and divided by the G-buffer albedo (irradiance times the BRDF's shape), so the
// cost of lighting fur does not grow with the number of lights. A sample is used only if the
// G-buffer shows this surface there within `tolerance` of the expected depth
// (FUR_OCCLUSION_TEST); otherwise the first neighbour that does. With FUR_STIPPLE, pixels of
// the fur's stipple class hold its outer-shell samples, not the base, and are skipped
// (include materials/techniques/stipple.glsl first).
#include "gbuffer/layout.glsl"

uniform sampler2D u_light_accumulation;
uniform sampler2D u_albedo_specular;
uniform sampler2D u_normal_exponent_id;
uniform sampler2D u_linear_depth;
uniform vec2 u_resolution;
uniform float u_surface_id;

ivec2 pixel_of(vec4 clip) {
    return ivec2(floor((clip.xy / clip.w * 0.5 + 0.5) * u_resolution));
}

bool inside(ivec2 pixel) {
    return all(greaterThanEqual(pixel, ivec2(0))) && all(lessThan(pixel, ivec2(u_resolution)));
}

// Whether the G-buffer at `pixel` (on the screen) holds this surface, at any depth.
bool holds_surface(ivec2 pixel) {
    return same_surface(texelFetch(u_normal_exponent_id, pixel, 0).w, u_surface_id);
}

// Whether `pixel` holds this fur within `tolerance` of `expected` linear depth.
bool holds_fur(ivec2 pixel, float expected, float tolerance) {
    if (!inside(pixel)) return false;
#ifdef FUR_OCCLUSION_TEST
    if (!holds_surface(pixel)) return false;
    if (abs(texelFetch(u_linear_depth, pixel, 0).r - expected) > tolerance) return false;
#endif
    return true;
}

// Whether the fragment's own pixel holds this surface (the last resort of a hidden base).
bool own_pixel_holds_fur() {
    return holds_surface(ivec2(gl_FragCoord.xy));
}

vec3 irradiance_at(ivec2 pixel) {
    vec3 albedo = max(texelFetch(u_albedo_specular, pixel, 0).rgb, vec3(1.0 / 255.0));
    return texelFetch(u_light_accumulation, pixel, 0).rgb / albedo;
}

const ivec2 AROUND[8] = ivec2[](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1),
                                ivec2(1, 1), ivec2(-1, 1), ivec2(1, -1), ivec2(-1, -1));

// The base sample: the pixel under the base point or the first neighbour holding the base.
bool base_irradiance(ivec2 pixel, float expected_depth, float tolerance,
                     out vec3 irradiance) {
    irradiance = vec3(0.0);
#ifdef FUR_STIPPLE
    bool stipple_pixel = stipple_sample(pixel);
#else
    bool stipple_pixel = false;
#endif
    if (!stipple_pixel && holds_fur(pixel, expected_depth, tolerance)) {
        irradiance = irradiance_at(pixel);
        return true;
    }
    for (int k = 0; k < 8; ++k) {
        ivec2 q = pixel + AROUND[k];
#ifdef FUR_STIPPLE
        if (stipple_sample(q)) continue;
#endif
        if (holds_fur(q, expected_depth, tolerance)) {
            irradiance = irradiance_at(q);
            return true;
        }
    }
    return false;
}
