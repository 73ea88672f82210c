// Silhouette strokes of hair tubes from the quads silhouette_edges.comp made (Costigan 4.3.7,
// Figs. 4.16-4.17): a corner of a stroke quad read back (NDC position, the view depth, the
// parameter along the strand and across the stroke, the strand), drawn by an indexed draw of
// two triangles a quad whose index count the compute pass wrote.
layout(std430, binding = 1) readonly buffer Strokes { float strokes[]; };

out vec2 g_stroke_uv;      // (along the strand, across the stroke 0..1)
out float g_view_depth;    // -z of the silhouette edge
flat out float g_strand;   // the strand's index

void main() {
    int at = gl_VertexID * 8;
    gl_Position = vec4(strokes[at], strokes[at + 1], strokes[at + 2], 1.0);
    g_view_depth = strokes[at + 3];
    g_stroke_uv = vec2(strokes[at + 4], strokes[at + 5]);
    g_strand = strokes[at + 6];
}
