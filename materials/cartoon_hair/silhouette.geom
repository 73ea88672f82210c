// Silhouette strokes of hair tubes, the GL 3.3 path (Costigan 4.3.7, Figs. 4.14-4.17; Lake et
// al., Northrup et al.). Input: a triangle with its neighbours (triangles_adjacency: 0, 2, 4
// the triangle; 1, 3, 5 the vertices opposite its edges 0-2, 2-4, 4-0 across them). An edge
// between a front- and a back-facing triangle is a silhouette edge; the front-facing triangle
// emits it (each edge once) as a quad (silhouette_stroke.glsl). With compute shaders the
// edges are found by silhouette_edges.comp and drawn by silhouette_strokes.vert instead.
layout(triangles_adjacency) in;
layout(triangle_strip, max_vertices = 12) out;

#include "materials/cartoon_hair/silhouette_stroke.glsl"

in vec3 vs_position[];
in vec3 vs_normal[];
in float vs_along[];
in float vs_strand[];

out vec2 g_stroke_uv;      // (along the strand, across the stroke 0..1)
out float g_view_depth;    // -z of the silhouette edge
flat out float g_strand;   // the strand's index

// > 0 front-facing (seen from the eye at the origin), <= 0 back-facing. A face without area
// (a tube tapered to a point) faces as its vertices' normals do.
float facing(int i, int j, int k) {
    vec3 a = vs_position[i];
    vec3 n = cross(vs_position[j] - a, vs_position[k] - a);
    vec3 e1 = vs_position[j] - a;
    vec3 e2 = vs_position[k] - a;
    if (dot(n, n) <= 1e-12 * dot(e1, e1) * dot(e2, e2)) {
        n = vs_normal[i] + vs_normal[j] + vs_normal[k];
        a = (vs_position[i] + vs_position[j] + vs_position[k]) / 3.0;
    }
    return -dot(n, a);
}

void emit_corner(vec4 clip, vec2 offset_pixels, vec2 uv, float view_depth) {
    gl_Position = stroke_corner(clip, offset_pixels);
    g_stroke_uv = uv;
    g_view_depth = view_depth;
    g_strand = vs_strand[0];
    EmitVertex();
}

void stroke(int i, int j) {
    vec4 c0, c1;
    vec2 e0, e1;
    if (!stroke_quad(vs_position[i], vs_position[j], vs_normal[i], vs_normal[j], vs_along[i],
                     vs_along[j], c0, c1, e0, e1)) return;
    float z0 = -vs_position[i].z;
    float z1 = -vs_position[j].z;
    emit_corner(c0, -e0, vec2(vs_along[i], 0.0), z0);
    emit_corner(c0, e0, vec2(vs_along[i], 1.0), z0);
    emit_corner(c1, -e1, vec2(vs_along[j], 0.0), z1);
    emit_corner(c1, e1, vec2(vs_along[j], 1.0), z1);
    EndPrimitive();
}

void main() {
    if (facing(0, 2, 4) <= 0.0) return;  // the front-facing triangle emits the edge
    if (facing(0, 1, 2) <= 0.0) stroke(0, 2);  // neighbour (0, 1, 2) winds as (a, p, b)
    if (facing(2, 3, 4) <= 0.0) stroke(2, 4);
    if (facing(4, 5, 0) <= 0.0) stroke(4, 0);
}
