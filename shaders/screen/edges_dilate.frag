// Screen: the one-pixel edge mask dilated to lines `width` pixels wide: a disc `width` pixels
// across (for an even width, centred between pixels).
uniform sampler2D u_edges_raw;
uniform int u_width;

out float out_edge;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_edges_raw, 0);
    int low = (u_width - 1) / 2;
    int high = u_width / 2;
    float centre = (u_width % 2 == 0) ? 0.5 : 0.0;
    float radius = 0.5 * float(u_width);
    float edge = 0.0;
    for (int y = -low; y <= high; ++y) {
        for (int x = -low; x <= high; ++x) {
            vec2 offset = vec2(float(x), float(y)) - centre;
            if (dot(offset, offset) > radius * radius + 1e-3) continue;  // a disc, not a square
            ivec2 q = p + ivec2(x, y);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            edge = max(edge, texelFetch(u_edges_raw, q, 0).r);
        }
    }
    out_edge = edge;
}
