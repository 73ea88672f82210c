// The separable subsurface blur (Jimenez et al. 2015): one direction (u_direction) of the
// diffuse light of subsurface pixels, by the taps of the pixel's profile
// (u_subsurface_profiles: materials/techniques/subsurface_profile.py), each at its world offset
// scaled to pixels at the pixel's depth. A tap on another surface (not subsurface, or farther
// in depth than three of the profile's widest shapes) takes the centre's light instead, so
// light does not bleed across silhouettes. BLUR_ADD (the second direction) writes the blurred
// light less the unblurred, added into the light accumulation (or forward's composition).
// Deferred, the pixel is subsurface by its shading model; forward (FORWARD_SUBSURFACE), by the
// mask pass's target.
#include "common/surface.glsl"

uniform sampler2D u_source;
uniform sampler2D u_subsurface_profiles;
uniform mat4 u_projection;
uniform vec2 u_resolution;
uniform vec2 u_direction;
#ifdef BLUR_ADD
uniform sampler2D u_diffuse_light;
#endif
#ifdef FORWARD_SUBSURFACE
uniform sampler2D u_subsurface_surface;
#else
uniform sampler2D u_linear_depth;
uniform sampler2D u_normal_exponent_id;
uniform sampler2D u_subsurface_profile;
uniform int u_subsurface_model;
#endif

out vec4 out_color;

// The view depth of the subsurface surface at a pixel (0: none there) and its profile row
vec2 subsurface_at(ivec2 pixel) {
#ifdef FORWARD_SUBSURFACE
    vec2 seen = texelFetch(u_subsurface_surface, pixel, 0).xy;
    return vec2(seen.x, seen.y - 1.0);
#else
    float id = texelFetch(u_normal_exponent_id, pixel, 0).a;
    if (id <= 0.0 || surface_shading_model(id) != u_subsurface_model) return vec2(0.0, -1.0);
    return vec2(texelFetch(u_linear_depth, pixel, 0).r,
                floor(texelFetch(u_subsurface_profile, pixel, 0).r * 255.0 + 0.5));
#endif
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec2 here = subsurface_at(pixel);
    if (here.x <= 0.0) discard;
    int row = int(here.y + 0.5);
    vec3 centre = texelFetch(u_source, pixel, 0).rgb;
    vec4 shape = texelFetch(u_subsurface_profiles, ivec2(0, row), 0);
    float tolerance = 3.0 * max(shape.r, max(shape.g, shape.b));
    // pixels a world unit spans at this depth, along the direction
    float focal = u_direction.x > 0.5 ? u_projection[0][0] * u_resolution.x
                                      : u_projection[1][1] * u_resolution.y;
    float scale = 0.5 * focal / here.x;
    ivec2 size = ivec2(u_resolution);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < SUBSURFACE_TAPS; ++k) {
        vec4 tap = texelFetch(u_subsurface_profiles, ivec2(1 + k, row), 0);
        ivec2 at = pixel + ivec2(round(u_direction * (tap.x * scale)));
        vec3 light = centre;
        if (all(greaterThanEqual(at, ivec2(0))) && all(lessThan(at, size))) {
            vec2 there = subsurface_at(at);
            if (there.x > 0.0 && abs(there.x - here.x) < tolerance)
                light = texelFetch(u_source, at, 0).rgb;
        }
        sum += tap.yzw * light;
    }
#ifdef BLUR_ADD
    out_color = vec4(sum - texelFetch(u_diffuse_light, pixel, 0).rgb, 0.0);
#else
    out_color = vec4(sum, 1.0);
#endif
}
