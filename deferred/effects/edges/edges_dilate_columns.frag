// Screen, second half of the edge dilation (see edges_dilate_rows.frag): a pixel is on the line
// where, for some row offset y within the width, the least squared horizontal offset found in
// that row plus (y - centre)^2 is within the disc of radius width / 2 (EDGE_RADII: the row's
// least x^2 - r^2 plus y^2 is at most 0).
uniform sampler2D u_row_offsets;
uniform int u_width;

out float out_edge;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    int size = textureSize(u_row_offsets, 0).y;
#ifdef EDGE_RADII
    int reach = u_width / 2;
    float edge = 0.0;
    for (int y = -reach; y <= reach; ++y) {
        int q = p.y + y;
        if (q < 0 || q >= size) continue;
        if (texelFetch(u_row_offsets, ivec2(p.x, q), 0).r + float(y * y) <= 1e-3) edge = 1.0;
    }
    out_edge = edge;
#else
    int low = (u_width - 1) / 2;
    int high = u_width / 2;
    float centre = (u_width % 2 == 0) ? 0.5 : 0.0;
    float radius = 0.5 * float(u_width);
    float edge = 0.0;
    for (int y = -low; y <= high; ++y) {
        int q = p.y + y;
        if (q < 0 || q >= size) continue;
        float offset = float(y) - centre;
        if (texelFetch(u_row_offsets, ivec2(p.x, q), 0).r + offset * offset <=
                radius * radius + 1e-3) {
            edge = 1.0;
        }
    }
    out_edge = edge;
#endif
}
