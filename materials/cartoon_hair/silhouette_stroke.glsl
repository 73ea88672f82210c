// A silhouette edge's stroke quad (Costigan 4.3.7, Figs. 4.16-4.17), shared by the geometry
// shader (silhouette.geom, the GL 3.3 path) and the stroke vertex shader that draws the edges a
// compute pass found (silhouette_strokes.vert): each end of the edge is pushed either side on
// screen along its vertex's normal as it projects (the edge's own normal where that looks
// along the edge or at the eye), so the quads of two edges meeting at a vertex share their
// corners there (the thesis' strip joints, Fig. 4.16, without chaining the edges), half the
// stroke's width each way: u_stroke_width pixels, or u_stroke_world_width view units at the
// vertex's depth, at most half the tube's radius there on screen. Without STROKE_ID_BUFFER the
// quad is pulled u_stroke_tolerance toward the eye (the forward pipeline's depth test; its
// place on screen does not change).
uniform mat4 u_projection;
uniform vec2 u_resolution;
uniform float u_stroke_width;        // pixels
uniform float u_stroke_world_width;  // view units at the stroke's depth (0: u_stroke_width)
uniform float u_tube_radius;         // view units at the root
uniform vec3 u_tube_taper;           // the radius along the strand: a x^2 + b x + c
uniform float u_stroke_tolerance;    // view units

vec4 stroke_clip(vec3 p) {
#ifndef STROKE_ID_BUFFER
    float distance_to_eye = length(p);
    p *= max(distance_to_eye - u_stroke_tolerance, 0.5 * distance_to_eye) / distance_to_eye;
#endif
    return u_projection * vec4(p, 1.0);
}

// Pixels a view unit at clip position c: the projection's y scale over w (the depth; 1 in an
// orthographic projection).
float stroke_pixels_per_unit(vec4 c) {
    return 0.5 * u_resolution.y * u_projection[1][1] / c.w;
}

// Half the stroke's width in pixels at a vertex `along` the strand, at clip position c.
float stroke_half_width(float along, vec4 c) {
    float scale = stroke_pixels_per_unit(c);
    float width = u_stroke_world_width > 0.0 ? u_stroke_world_width * scale : u_stroke_width;
    float radius = u_tube_radius * max((u_tube_taper.x * along + u_tube_taper.y) * along +
                                       u_tube_taper.z, 0.0);
    return 0.5 * min(width, radius * scale);
}

// The screen direction (pixels, unit) the vertex normal n points in at clip position c; the
// edge's own normal `across` where the vertex normal looks along the edge or at the eye.
vec2 stroke_extrusion(vec3 n, vec4 c, vec2 across) {
    vec4 cn = u_projection * vec4(n, 0.0);
    vec2 d = (cn.xy * c.w - c.xy * cn.w) * u_resolution;  // d(c.xy / c.w), times c.w^2 > 0
    float len = length(d);
    if (len < 1e-6) return across;
    d /= len;
    float along_across = dot(d, across);
    if (abs(along_across) < 0.3) return across;
    return along_across < 0.0 ? -d : d;
}

// The stroke of the edge p0 p1 (view space; normals n0, n1; along0, along1): its two ends'
// clip positions c0, c1 and their offsets in pixels e0, e1 (each end's corners are c -/+ e).
// False where no stroke is drawn (behind the eye, or seen end-on).
bool stroke_quad(vec3 p0, vec3 p1, vec3 n0, vec3 n1, float along0, float along1,
                 out vec4 c0, out vec4 c1, out vec2 e0, out vec2 e1) {
    c0 = stroke_clip(p0);
    c1 = stroke_clip(p1);
    e0 = e1 = vec2(0.0);
    if (c0.w <= 1e-6 || c1.w <= 1e-6) return false;  // behind the eye (no clipping here)
    vec2 s0 = c0.xy / c0.w * 0.5 * u_resolution;
    vec2 s1 = c1.xy / c1.w * 0.5 * u_resolution;
    vec2 d = s1 - s0;
    float len = length(d);
    if (len < 1e-3) return false;  // an edge seen end-on
    vec2 across = vec2(-d.y, d.x) / len;
    e0 = stroke_extrusion(n0, c0, across) * stroke_half_width(along0, c0);
    e1 = stroke_extrusion(n1, c1, across) * stroke_half_width(along1, c1);
    return true;
}

// A corner's clip position: c moved by `offset_pixels` on screen.
vec4 stroke_corner(vec4 c, vec2 offset_pixels) {
    c.xy += offset_pixels * 2.0 / u_resolution * c.w;
    return c;
}
