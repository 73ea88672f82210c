// Screen, first half of the edge dilation: for each pixel, the least squared horizontal offset
// (x - centre)^2 to an edge pixel of its row within the line's width, or NO_EDGE. The second
// half (edges_dilate_columns.frag) adds (y - centre)^2 down the column: a pixel is on the line
// where some row's least value plus its own offset is within the disc, so the two passes give
// exactly the disc `width` pixels across (for an even width, centred between pixels) at a cost
// that grows with the width, not its square (the thesis' dilation, its Table 5.4, grew faster).
uniform sampler2D u_edges_raw;
uniform int u_width;

out float out_offset;

const float NO_EDGE = 1.0e4;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    int size = textureSize(u_edges_raw, 0).x;
    int low = (u_width - 1) / 2;
    int high = u_width / 2;
    float centre = (u_width % 2 == 0) ? 0.5 : 0.0;
    float least = NO_EDGE;
    for (int x = -low; x <= high; ++x) {
        int q = p.x + x;
        if (q < 0 || q >= size) continue;
        if (texelFetch(u_edges_raw, ivec2(q, p.y), 0).r > 0.5) {
            float offset = float(x) - centre;
            least = min(least, offset * offset);
        }
    }
    out_offset = least;
}
