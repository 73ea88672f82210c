// Weighted blended order-independent transparency, composition over what lies behind
// (McGuire and Bavoil 2013, Eq. 6 per channel): the weighted mean of the layers' emitted
// light per unit of coverage, times the light they cover, plus what lies behind times what
// they reveal, read through the sum of the layers' refraction offsets.
uniform sampler2D u_glass_accum;
uniform sampler2D u_glass_coverage;
uniform sampler2D u_glass_revealage;
uniform sampler2D u_glass_refraction;
uniform sampler2D u_glass_background;

in vec2 v_uv;
out vec4 out_color;

// a refraction offset in units of the frame's height, in UV units
vec2 screen_offset(vec2 offset) {
    vec2 size = vec2(textureSize(u_glass_background, 0));
    return offset * vec2(size.y / size.x, 1.0);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 behind = texelFetch(u_glass_background, pixel, 0);
    vec3 revealage = texelFetch(u_glass_revealage, pixel, 0).rgb;
    if (all(greaterThanEqual(revealage, vec3(1.0)))) {  // no glass at this pixel
        out_color = behind;
        return;
    }
    vec4 accum = texelFetch(u_glass_accum, pixel, 0);
    vec3 coverage = texelFetch(u_glass_coverage, pixel, 0).rgb;
    vec2 offset = texelFetch(u_glass_refraction, pixel, 0).xy;
    vec3 seen = texture(u_glass_background, v_uv + screen_offset(offset)).rgb;
    vec3 emitted = accum.rgb / max(coverage, vec3(1e-6)) * (1.0 - revealage);
    out_color = vec4(emitted + seen * revealage, behind.a);
}
