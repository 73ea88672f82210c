// Screen, first half of the edge dilation: for each pixel, the least squared horizontal offset
// (x - centre)^2 to an edge pixel of its row within the line's width, or NO_EDGE. The second
// half (edges_dilate_columns.frag) adds (y - centre)^2 down the column: a pixel is on the line
// where some row's least value plus its own offset is within the disc, so the two passes give
// exactly the disc `width` pixels across (for an even width, centred between pixels) at a cost
// that grows with the width, not its square (the thesis' dilation, its Table 5.4, grew faster).
// EDGE_RADII (lines in world units): each edge pixel holds its own radius r (edges.frag), and
// the value is the least x^2 - r^2 over the row within u_width / 2: the column's least of it
// plus y^2 is at most 0 exactly inside the union of the edge pixels' discs.
uniform sampler2D u_edges_raw;
uniform int u_width;

out float out_offset;

const float NO_EDGE = 1.0e4;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    int size = textureSize(u_edges_raw, 0).x;
#ifdef EDGE_RADII
    int reach = u_width / 2;
    float least = NO_EDGE;
    for (int x = -reach; x <= reach; ++x) {
        int q = p.x + x;
        if (q < 0 || q >= size) continue;
        float radius = texelFetch(u_edges_raw, ivec2(q, p.y), 0).r;
        if (radius > 0.0) least = min(least, float(x * x) - radius * radius);
    }
    out_offset = least;
#else
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
#endif
}
