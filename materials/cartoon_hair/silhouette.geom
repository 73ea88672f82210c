// Silhouette strokes of hair tubes (Costigan 4.3.7, Figs. 4.14-4.17; Lake et al., Northrup et
// al.). Input: a triangle with its neighbours (triangles_adjacency: 0, 2, 4 the triangle; 1, 3,
// 5 the vertices opposite its edges 0-2, 2-4, 4-0 across them). An edge between a front- and a
// back-facing triangle is a silhouette edge; the front-facing triangle emits it (each edge
// once) as a quad u_stroke_width pixels (or u_stroke_world_width view units) wide, at most the
// tube's radius, extruded in screen space either side of the edge
// along its vertices' normals as they project on screen, so the quads of neighbouring edges
// meet at their shared vertices (the thesis' strip joints, Fig. 4.16, without chaining the
// edges). Without STROKE_ID_BUFFER the quad is pulled u_stroke_tolerance toward the eye (the
// forward pipeline's depth test; its position on screen does not change).
layout(triangles_adjacency) in;
layout(triangle_strip, max_vertices = 12) out;

in vec3 vs_position[];
in vec3 vs_normal[];
in float vs_along[];
in float vs_strand[];

uniform mat4 u_projection;
uniform vec2 u_resolution;
uniform float u_stroke_width;        // pixels
uniform float u_stroke_world_width;  // view units at the stroke's depth (0: u_stroke_width)
uniform float u_tube_radius;         // view units at the root
uniform vec3 u_tube_taper;           // the radius along the strand: a x^2 + b x + c
uniform float u_stroke_tolerance;    // view units

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

vec4 pulled_clip(vec3 p) {
#ifndef STROKE_ID_BUFFER
    float distance_to_eye = length(p);
    p *= max(distance_to_eye - u_stroke_tolerance, 0.5 * distance_to_eye) / distance_to_eye;
#endif
    return u_projection * vec4(p, 1.0);
}

void emit_corner(vec4 clip, vec2 offset_pixels, vec2 uv, float view_depth) {
    clip.xy += offset_pixels * 2.0 / u_resolution * clip.w;
    gl_Position = clip;
    g_stroke_uv = uv;
    g_view_depth = view_depth;
    g_strand = vs_strand[0];
    EmitVertex();
}

// The screen direction (pixels, unit) the vertex normal points in at clip position c; the
// edge's own normal ``across`` where the vertex normal looks along the edge or at the eye.
vec2 extrusion(int i, vec4 c, vec2 across) {
    vec4 cn = u_projection * vec4(vs_normal[i], 0.0);
    vec2 d = (cn.xy * c.w - c.xy * cn.w) * u_resolution;  // d(c.xy / c.w), times c.w^2 > 0
    float len = length(d);
    if (len < 1e-6) return across;
    d /= len;
    float along_across = dot(d, across);
    if (abs(along_across) < 0.3) return across;
    return along_across < 0.0 ? -d : d;
}

// Pixels a view unit at clip position c: the projection's y scale over w (the depth; 1 in an
// orthographic projection).
float pixels_per_unit(vec4 c) {
    return 0.5 * u_resolution.y * u_projection[1][1] / c.w;
}

// Half the stroke's width in pixels at vertex i: u_stroke_width pixels, or u_stroke_world_width
// view units there; at most half the tube's radius there on screen, so a stroke never buries a
// thin (far, or tapering) tube: at least half of each tube's width keeps its colour.
float half_width(int i, vec4 c) {
    float scale = pixels_per_unit(c);
    float width = u_stroke_world_width > 0.0 ? u_stroke_world_width * scale : u_stroke_width;
    float x = vs_along[i];
    float radius = u_tube_radius * max((u_tube_taper.x * x + u_tube_taper.y) * x + u_tube_taper.z,
                                       0.0);
    return 0.5 * min(width, radius * scale);
}

void stroke(int i, int j) {
    vec4 c0 = pulled_clip(vs_position[i]);
    vec4 c1 = pulled_clip(vs_position[j]);
    if (c0.w <= 1e-6 || c1.w <= 1e-6) return;  // behind the eye: no stroke (no clipping here)
    vec2 s0 = c0.xy / c0.w * 0.5 * u_resolution;
    vec2 s1 = c1.xy / c1.w * 0.5 * u_resolution;
    vec2 d = s1 - s0;
    float len = length(d);
    if (len < 1e-3) return;  // an edge seen end-on
    vec2 across = vec2(-d.y, d.x) / len;
    // Each end is pushed along its vertex's normal on screen: the edges meeting at a vertex
    // push it alike, so neighbouring quads join without gaps or overlaps (no chaining).
    vec2 e0 = extrusion(i, c0, across) * half_width(i, c0);
    vec2 e1 = extrusion(j, c1, across) * half_width(j, c1);
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
