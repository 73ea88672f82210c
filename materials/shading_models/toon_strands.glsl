// Toon shading of strands (Costigan 4.3.3-4.3.6 on the hair's tubes): the toon model's ramp
// (toon.glsl) for the diffuse, and a specular that follows the strand where the surface has a
// tangent (the G-buffer datum strand_tangent): Kajiya-Kay's sin(T, H) = sqrt(1 - (T.H)^2), the
// largest N.H over the normals round the strand, takes the place of N.H in both of 4.3.6's
// methods, the Blinn band (exponent and intensity from the G-buffer, thresholded to a hard
// edge) and the X-toon ramp's specular metric. The highlight is then a band across the strands
// where they run perpendicular to H (the anime "ring"), the full width of each tube, instead
// of a dot a few pixels wide on each tube's curve. A surface without a tangent (the head; the
// datum's sentinel TOON_NO_TANGENT) keeps the toon model's N.H: the skin's own highlight.
#include "materials/shading_models/toon.glsl"
#include "materials/techniques/strand_tangent.glsl"

const float TOON_NO_TANGENT = 4.0;  // strand_tangent.u of a surface without a strand

vec4 toon_strands_no_tangent() {
    return vec4(TOON_NO_TANGENT, 0.0, 0.0, 0.0);
}

// sin(T, H) where the surface has a strand tangent, else N.H.
float toon_strands_alignment(Surface s, vec3 H) {
    if (abs(s.data.strand_tangent.x) > 2.0) return max(dot(s.normal, H), 0.0);
    vec3 T = strand_tangent_decode(s.data.strand_tangent);
    float t_dot_h = dot(T, H);
    return sqrt(max(1.0 - t_dot_h * t_dot_h, 0.0));
}

vec3 toon_strands(Surface s, vec3 L, vec3 V, vec3 radiance) {
    vec3 H = normalize(L + V);
    float alignment = toon_strands_alignment(s, H);
    float layer = floor(s.data.toon_ramp.r * 255.0 + 0.5);
    vec4 constants = texelFetch(u_toon_ramp_constants, ivec2(int(layer), 0), 0);
    vec3 ramp;
    if (constants.w > 0.5 && int(constants.x + 0.5) == 3) {  // the specular metric, (align)^c
        ivec3 size = textureSize(u_toon_ramps, 0);
        float x = clamp(dot(s.normal, L), 0.0, 1.0);
        float y = pow(alignment, constants.y);
        ivec2 texel = min(ivec2(vec2(x, y) * vec2(size.xy)), size.xy - 1);
        ramp = texelFetch(u_toon_ramps, ivec3(texel, int(layer)), 0).rgb;
    } else {
        ramp = toon_ramp(s, L, V, layer);
    }
    float highlight = pow(alignment, s.specular_exponent);
    // a strand's band crosses the whole tube (its lit side and the rest), a surface's its lit side
    float facing = abs(s.data.strand_tangent.x) > 2.0 ? dot(s.normal, L) : 1.0;
    float band = facing > 0.0 ? smoothstep(0.45, 0.55, highlight) : 0.0;
    return radiance * (s.albedo * ramp + vec3(s.specular_intensity * band));
}
