// Temporal anti-aliasing, the sharpen (deferred.effects.taa): the resolved frame into the
// composition buffer, less its 4-neighbour blur by u_sharpen (0: a copy); in the compressed
// colours of the resolve, so an edge against a bright light gets no dark halo.
uniform sampler2D u_taa_resolved;
uniform float u_sharpen;

out vec4 out_color;

float luma(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

vec3 compress(vec3 c) {
    return c / (1.0 + luma(c));
}

vec3 expand(vec3 c) {
    return c / max(1.0 - luma(c), 1e-4);
}

vec3 fetch(ivec2 pixel) {
    ivec2 size = textureSize(u_taa_resolved, 0);
    return compress(max(texelFetch(u_taa_resolved, clamp(pixel, ivec2(0), size - 1), 0).rgb,
                        vec3(0.0)));
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 centre = texelFetch(u_taa_resolved, pixel, 0);
    if (u_sharpen <= 0.0) {
        out_color = centre;
        return;
    }
    vec3 c = fetch(pixel);
    vec3 blur = 0.25 * (fetch(pixel + ivec2(1, 0)) + fetch(pixel + ivec2(-1, 0)) +
                        fetch(pixel + ivec2(0, 1)) + fetch(pixel + ivec2(0, -1)));
    vec3 sharpened = clamp(c + u_sharpen * (c - blur), vec3(0.0), vec3(0.999));
    out_color = vec4(expand(sharpened), centre.a);
}
