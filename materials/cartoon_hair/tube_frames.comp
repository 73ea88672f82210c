// Tube rings on the GPU, first dispatch (Costigan 4.3.1; materials/techniques/hair_tubes.py's
// GpuTubes, the arithmetic of build_tubes): an invocation a strand samples its Catmull-Rom
// spline and the spline's slope (Ogre's SimpleSpline, as catmull_rom_weights: the Hermite curve
// of the segment a sample falls in, with tangents (P[k+1] - P[k-1]) / 2, one-sided at the
// ends), and carries the ring's first direction along it by rotation-minimising frames (Wang et
// al.'s double reflection), which is sequential along the strand. Out, for tube_vertices.comp:
// each sample's centre, and its normal and binormal times the ring's radius (the quadratic
// taper, 4.3.2), taken to the object's space by u_to_object (a ring's vertices are linear in
// the three, so they land where build_tubes' vertices moved by the matrix do).
// llvmpipe loads and stores a storage buffer lane by lane and a uniform array indexed in a
// loop likewise: the points and frames are vec4s and nothing indexes a uniform array.
layout(local_size_x = TUBE_GROUP) in;

// (strands, points + 1) vec4: each strand's points, root first, then the reference direction
// across its root (the first ring's orientation)
layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
// (strands, samples, 3) vec4: centre, radius x normal, radius x binormal
layout(std430, binding = 2) writeonly buffer Frames { vec4 frames[]; };

uniform int u_strands;
uniform int u_points;
uniform int u_samples;
uniform float u_radius;
uniform vec3 u_taper;  // the radius along the strand: a x^2 + b x + c, below 0 taken as 0
uniform mat4 u_to_object;

void main() {
    int s = int(gl_GlobalInvocationID.x);
    if (s >= u_strands) {
        return;
    }
    // the smallest squared length a reflection divides by (build_tubes' tiny * 1e6)
    const float EPS = 1.17549435e-32;
    int first = s * (u_points + 1);
    int last_point = u_points - 1;
    mat3 linear = mat3(u_to_object);
    vec3 previous_point = vec3(0.0);
    vec3 previous_tangent = vec3(0.0);
    vec3 r = vec3(0.0);
    for (int i = 0; i < u_samples; ++i) {
        float t = float(i * last_point) / float(u_samples - 1);
        int k = min(int(t), u_points - 2);
        float u = t - float(k);
        vec3 p0 = points[first + max(k - 1, 0)].xyz;
        vec3 p1 = points[first + k].xyz;
        vec3 p2 = points[first + k + 1].xyz;
        vec3 p3 = points[first + min(k + 2, last_point)].xyz;
        vec3 m1 = 0.5 * (p2 - p0);
        vec3 m2 = 0.5 * (p3 - p1);
        float uu = u * u;
        float uuu = uu * u;
        vec3 centre = (2.0 * uuu - 3.0 * uu + 1.0) * p1 + (uuu - 2.0 * uu + u) * m1
                    + (-2.0 * uuu + 3.0 * uu) * p2 + (uuu - uu) * m2;
        vec3 slope = (6.0 * uu - 6.0 * u) * p1 + (3.0 * uu - 4.0 * u + 1.0) * m1
                   + (-6.0 * uu + 6.0 * u) * p2 + (3.0 * uu - 2.0 * u) * m2;
        slope *= float(last_point);
        vec3 tangent = slope / max(length(slope), 1e-20);
        if (i == 0) {
            vec3 reference = points[first + u_points].xyz;
            r = reference - dot(reference, tangent) * tangent;
            r /= max(length(r), 1e-12);
        } else {
            // reflect the last frame in the bisector plane of the step, then in the one that
            // takes the reflected tangent onto this one
            vec3 v1 = centre - previous_point;
            float c1 = dot(v1, v1);
            float k1 = c1 > EPS ? 2.0 / c1 : 0.0;
            vec3 r_l = r - (k1 * dot(v1, r)) * v1;
            vec3 t_l = previous_tangent - (k1 * dot(v1, previous_tangent)) * v1;
            vec3 v2 = tangent - t_l;
            float c2 = dot(v2, v2);
            float k2 = c2 > EPS ? 2.0 / c2 : 0.0;
            r = r_l - (k2 * dot(v2, r_l)) * v2;
        }
        float x = float(i) / float(u_samples - 1);
        float radius = u_radius * max((u_taper.x * x + u_taper.y) * x + u_taper.z, 0.0);
        int at = (s * u_samples + i) * 3;
        frames[at] = vec4((u_to_object * vec4(centre, 1.0)).xyz, 0.0);
        frames[at + 1] = vec4(radius * (linear * r), 0.0);
        frames[at + 2] = vec4(radius * (linear * cross(tangent, r)), 0.0);
        previous_point = centre;
        previous_tangent = tangent;
    }
}
