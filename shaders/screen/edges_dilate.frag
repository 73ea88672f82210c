// Screen: the edge mask dilated to lines `width` pixels wide (a disc of radius width - 1).
uniform sampler2D u_edges_raw;
uniform int u_width;

out float out_edge;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_edges_raw, 0);
    int r = u_width - 1;
    float edge = 0.0;
    for (int y = -r; y <= r; ++y) {
        for (int x = -r; x <= r; ++x) {
            if (x * x + y * y > r * r + r) continue;  // a disc, not a square
            ivec2 q = p + ivec2(x, y);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            edge = max(edge, texelFetch(u_edges_raw, q, 0).r);
        }
    }
    out_edge = edge;
}
