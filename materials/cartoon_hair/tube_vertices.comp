// Tube rings on the GPU, second dispatch (Costigan 4.3.2; materials/techniques/hair_tubes.py's
// GpuTubes, the same arithmetic as build_tubes): an invocation a ring, writing its vertices
// (and, on the end rings, the cap's centre) into the mesh's own vertex buffer: position and
// normal, the rest of the vertex being constant. Vertex j of sample i is the sample's centre
// plus its radius along cos a_j normal + sin a_j binormal; its normal the area-weighted sum of
// the six triangles round it (the quads before and after it, and the cap's fan on an end ring),
// built from the rings of samples i - 1, i, i + 1 (tube_frames.comp's frames), walked round with
// the vertices j - 1, j, j + 1 of each at hand; a cap centre's normal the sum of its fan.
// Invocations run strand-major (a strand's rings, root first, then the next strand's): llvmpipe
// stores to a storage buffer lane by lane, and neighbouring lanes then write neighbouring
// memory (ring-major took about 1.7 times the CPU time). The loop over a ring has no division.
// The rings come in the object's space (tube_frames.comp): the triangles' normals are there
// the matrix's inverse transpose times build_tubes', times its determinant (u_orientation, the
// determinant's sign, turns them back out of a mirrored object).
layout(local_size_x = TUBE_GROUP) in;

// (strands, samples, 3) vec4: centre, radius x normal, radius x binormal
layout(std430, binding = 2) readonly buffer Frames { vec4 frames[]; };
// the mesh's interleaved vertices, u_stride floats each, position then normal first
layout(std430, binding = 3) buffer Vertices { float vertices[]; };

uniform int u_strands;
uniform int u_samples;
uniform int u_sides;
uniform int u_stride;
uniform vec2 u_turn;  // cos and sin of 2 pi / u_sides
uniform float u_orientation;  // 1, or -1 where the object's matrix mirrors

struct Ring {
    vec3 centre;
    vec3 normal;    // radius times the frame's normal
    vec3 binormal;  // radius times its binormal
};

Ring load(int s, int i) {
    int at = (s * u_samples + i) * 3;
    return Ring(frames[at].xyz, frames[at + 1].xyz, frames[at + 2].xyz);
}

// the ring's vertex at angle (cos, sin)
vec3 at(Ring ring, vec2 angle) {
    return ring.centre + angle.x * ring.normal + angle.y * ring.binormal;
}

vec3 unit_or_zero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

void write_vertex(int v, vec3 position, vec3 normal) {
    int base = v * u_stride;
    vertices[base] = position.x;
    vertices[base + 1] = position.y;
    vertices[base + 2] = position.z;
    vertices[base + 3] = normal.x;
    vertices[base + 4] = normal.y;
    vertices[base + 5] = normal.z;
}

void main() {
    int r = int(gl_GlobalInvocationID.x);
    if (r >= u_strands * u_samples) {
        return;
    }
    int s = r / u_samples;
    int i = r - s * u_samples;
    int last = u_samples - 1;
    bool behind = i > 0;
    bool ahead = i < last;
    Ring back = load(s, behind ? i - 1 : i);
    Ring here = load(s, i);
    Ring front = load(s, ahead ? i + 1 : i);
    vec3 centre = here.centre;
    // vertices j - 1, j and j + 1 of the three rings
    // vertex j's angle turned a side at a time from (1, 0) (no table: see tube_frames.comp)
    vec2 angle = vec2(1.0, 0.0);
    vec2 before = vec2(u_turn.x, -u_turn.y);
    vec3 back_j = at(back, angle);
    vec3 left = at(here, before), position = at(here, angle);
    vec3 front_left = at(front, before), front_j = at(front, angle);
    vec3 fan = vec3(0.0);  // the end ring's cap: the sum of its triangles
    int first = s * (u_samples * u_sides + 2) + i * u_sides;
    for (int j = 0; j < u_sides; ++j) {
        angle = j + 1 == u_sides ? vec2(1.0, 0.0)
              : vec2(angle.x * u_turn.x - angle.y * u_turn.y,
                     angle.y * u_turn.x + angle.x * u_turn.y);
        vec3 back_right = at(back, angle);
        vec3 right = at(here, angle);
        vec3 front_right = at(front, angle);
        // the cap's triangles (centre, j, j+1) and (centre, j-1, j), wound outward: the tip's
        // as seen along the strand, the root's against it
        vec3 cap = cross(position - centre, right - centre);
        vec3 caps = cap + cross(left - centre, position - centre);
        vec3 total;
        if (ahead) {  // (i j, i j+1, i+1 j) and the whole quad (i, j-1)
            total = cross(right - position, front_j - position)
                  + cross(front_j - left, front_left - position);
        } else {
            total = caps;
        }
        if (behind) {  // the whole quad (i-1, j) and (i-1 j, i j, i j-1)
            total += cross(right - back_j, position - back_right)
                   + cross(position - back_j, left - back_j);
        } else {
            total -= caps;
        }
        fan += cap;
        write_vertex(first + j, position, unit_or_zero(u_orientation * total));
        back_j = back_right;
        left = position;
        position = right;
        front_left = front_j;
        front_j = front_right;
    }
    if (!behind || !ahead) {  // the cap's centre: the root cap's after the rings, then the tip's
        int centre_vertex = s * (u_samples * u_sides + 2) + u_samples * u_sides + (behind ? 1 : 0);
        write_vertex(centre_vertex, centre, unit_or_zero(u_orientation * (behind ? fan : -fan)));
    }
}
