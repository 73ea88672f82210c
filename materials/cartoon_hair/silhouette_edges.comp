// Silhouette strokes of hair tubes on the GPU (Costigan 4.3.7, Figs. 4.14-4.17): an invocation
// a strand walks its tube ring by ring (hair_tubes.py's vertex order: ring i vertex j at
// i * sides + j, then the root cap's centre, then the tip's), each vertex read and each
// triangle's facing found once, and classifies the edges of the tube's fixed adjacency:
//   ring i's edges (i j, i j+1), between A(i, j) = (i j, i j+1, i+1 j) and
//     B(i-1, j) = (i-1 j+1, i j+1, i j) (the caps' fans at the ends);
//   toward ring i + 1, the along edges (i j, i+1 j), between A(i, j) and B(i, j-1), and the
//     diagonals (i j+1, i+1 j), between A(i, j) and B(i, j) = (i j+1, i+1 j+1, i+1 j);
//   on an end ring, its cap's spokes (centre, i j), between the fan's triangles j - 1 and j.
// An edge between a front- and a back-facing triangle is a silhouette edge (the facing is
// silhouette.geom's: the triangle's normal against the eye, or, without area, its vertices'
// normals). Its stroke quad (silhouette_stroke.glsl) is made here, once, its 4 corners
// written to the stroke buffer (8 floats a corner: NDC x, y, z, the view depth, the parameter
// along the strand and across the stroke, the strand, one unused), and the indirect draw
// command's index count grows by the quad's 6; silhouette_strokes.vert only reads the
// corners back. Past the buffer's capacity strokes are dropped. With STROKE_ID_BUFFER
// (deferred) a stroke whose ends, middle and corners silhouette.frag would all discard is not
// made at all.
layout(local_size_x = EDGE_GROUP) in;

#include "materials/cartoon_hair/silhouette_stroke.glsl"

layout(std430, binding = 0) readonly buffer Vertices { float vertices[]; };
layout(std430, binding = 1) writeonly buffer Strokes { float strokes[]; };
// DrawElementsIndirectCommand: count (6 indices a stroke), instance count (1), first index,
// base vertex, base instance
layout(std430, binding = 2) buffer Command { uint command[5]; };

uniform int u_strands;
uniform int u_samples;
uniform int u_sides;
uniform int u_stride;  // floats a vertex
uniform uint u_capacity;  // strokes the buffer holds
uniform mat4 u_model_view;
uniform mat3 u_normal_matrix;
#ifdef STROKE_ID_BUFFER
// Hidden strokes are not made: silhouette.frag draws a stroke's fragment where the G-buffer
// holds the stroke's own strand, or where the stroke lies at most u_stroke_tolerance behind
// the G-buffer's depth; a stroke failing both at its ends, its middle and its four corners
// would draw nothing (all but slivers of it), and in dense hair most do.
uniform sampler2D u_linear_depth;
uniform sampler2D u_strand_id;
uniform float u_strand_base;

bool hidden(vec4 clip, float strand) {
    vec2 pixel = (clip.xy / clip.w * 0.5 + 0.5) * u_resolution;
    ivec2 size = textureSize(u_linear_depth, 0);
    if (any(lessThan(pixel, vec2(0.0))) || any(greaterThanEqual(pixel, vec2(size)))) return false;
    float scene = texelFetch(u_linear_depth, ivec2(pixel), 0).r;  // 0: background
    float id = texelFetch(u_strand_id, ivec2(pixel), 0).r;
    bool own = abs(id - (u_strand_base + strand + 1.0)) < 0.5;
    return !own && scene > 0.0 && clip.w - u_stroke_tolerance > scene;
}
#endif

const int MAX_SIDES = 16;

struct Vertex {
    vec3 position;  // view space
    vec3 normal;    // view space
};

Vertex load(int v) {
    int at = v * u_stride;
    vec3 p = vec3(vertices[at], vertices[at + 1], vertices[at + 2]);
    vec3 n = vec3(vertices[at + 3], vertices[at + 4], vertices[at + 5]);
    return Vertex((u_model_view * vec4(p, 1.0)).xyz, u_normal_matrix * n);
}

// > 0 front-facing (seen from the eye at the origin), <= 0 back-facing.
float facing(Vertex a, Vertex b, Vertex c) {
    vec3 e1 = b.position - a.position;
    vec3 e2 = c.position - a.position;
    vec3 n = cross(e1, e2);
    vec3 at = a.position;
    if (dot(n, n) <= 1e-12 * dot(e1, e1) * dot(e2, e2)) {
        n = a.normal + b.normal + c.normal;
        at = (a.position + b.position + c.position) / 3.0;
    }
    return -dot(n, at);
}

void write_corner(uint slot, int corner, vec4 clip, float along, float across, float depth,
                  float strand) {
    int at = (int(slot) * 4 + corner) * 8;
    strokes[at] = clip.x / clip.w;
    strokes[at + 1] = clip.y / clip.w;
    strokes[at + 2] = clip.z / clip.w;
    strokes[at + 3] = depth;
    strokes[at + 4] = along;
    strokes[at + 5] = across;
    strokes[at + 6] = strand;
}

// The stroke of the edge a b where one of its triangles faces the eye and the other not.
void emit(bool first_front, float second, Vertex a, Vertex b, float along_a, float along_b,
          float strand) {
    if (first_front == (second > 0.0)) return;
    vec4 c0, c1;
    vec2 e0, e1;
    if (!stroke_quad(a.position, b.position, a.normal, b.normal, along_a, along_b, c0, c1,
                     e0, e1)) return;
#ifdef STROKE_ID_BUFFER
    if (hidden(c0, strand) && hidden(c1, strand) && hidden(0.5 * (c0 + c1), strand) &&
        hidden(stroke_corner(c0, -e0), strand) && hidden(stroke_corner(c1, -e1), strand) &&
        hidden(stroke_corner(c0, e0), strand) && hidden(stroke_corner(c1, e1), strand)) return;
#endif
    uint slot = atomicAdd(command[0], 6u) / 6u;
    if (slot >= u_capacity) {
        atomicAdd(command[0], uint(-6));
        return;
    }
    float depth_a = -a.position.z;
    float depth_b = -b.position.z;
    write_corner(slot, 0, stroke_corner(c0, -e0), along_a, 0.0, depth_a, strand);
    write_corner(slot, 1, stroke_corner(c0, e0), along_a, 1.0, depth_a, strand);
    write_corner(slot, 2, stroke_corner(c1, -e1), along_b, 0.0, depth_b, strand);
    write_corner(slot, 3, stroke_corner(c1, e1), along_b, 1.0, depth_b, strand);
}

void main() {
    int s = int(gl_GlobalInvocationID.x);
    if (s >= u_strands) return;
    int last = u_samples - 1;
    int sides = u_sides;
    int base = s * (u_samples * sides + 2);
    float strand = float(s);
    Vertex here[MAX_SIDES];
    Vertex ahead[MAX_SIDES];
    float a_row[MAX_SIDES];     // A(i, j)
    float b_row[MAX_SIDES];     // B(i, j)
    float b_behind[MAX_SIDES];  // B(i-1, j)
    float fan[MAX_SIDES];       // the cap's triangle j at an end ring
    for (int j = 0; j < sides; ++j) {
        here[j] = load(base + j);
        ahead[j] = load(base + sides + j);
    }
    Vertex root = load(base + u_samples * sides);
    Vertex tip = load(base + u_samples * sides + 1);
    for (int i = 0; i <= last; ++i) {
        float along_here = float(i) / float(last);
        float along_ahead = float(i + 1) / float(last);
        Vertex centre = i == 0 ? root : tip;
        for (int j = 0; j < sides; ++j) {
            int k = j + 1 == sides ? 0 : j + 1;
            if (i < last) {
                a_row[j] = facing(here[j], here[k], ahead[j]);
                b_row[j] = facing(here[k], ahead[k], ahead[j]);
            }
            if (i == 0) fan[j] = facing(root, here[k], here[j]);
            if (i == last) fan[j] = facing(tip, here[j], here[k]);
        }
        for (int j = 0; j < sides; ++j) {
            int k = j + 1 == sides ? 0 : j + 1;
            int previous = j == 0 ? sides - 1 : j - 1;
            float toward = i < last ? a_row[j] : fan[j];
            float away = i > 0 ? b_behind[j] : fan[j];
            emit(toward > 0.0, away, here[j], here[k], along_here, along_here, strand);
            if (i < last) {
                emit(a_row[j] > 0.0, b_row[previous], here[j], ahead[j], along_here,
                     along_ahead, strand);
                emit(a_row[j] > 0.0, b_row[j], here[k], ahead[j], along_here, along_ahead,
                     strand);
            }
            if (i == 0 || i == last) {
                emit(fan[previous] > 0.0, fan[j], centre, here[j], i == 0 ? 0.0 : 1.0,
                     along_here, strand);
            }
        }
        if (i < last) {
            for (int j = 0; j < sides; ++j) {
                b_behind[j] = b_row[j];
                here[j] = ahead[j];
                if (i + 2 <= last) ahead[j] = load(base + (i + 2) * sides + j);
            }
        }
    }
}
