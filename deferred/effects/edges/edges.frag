// Screen: edges from the clean G-buffer (before any stipple, Revie 2.4.2), drawn on the near
// side of each discontinuity so a line is one pixel wide before dilation:
//  - ids: a 4-neighbour of another surface id that lies farther away (silhouettes, material
//    boundaries), or, where the scene's materials write strand_id (cartoon hair), of another
//    clump (strand_id.g): the hair against the head and clumps over clumps, not every strand;
//  - creases: the normal turns by more than u_crease_angle between two 4-neighbours of one
//    surface (one strand), and by more than CURVE_RATIO times the turn of the steps either side
//    along the same line. A smooth surface's normal turns step by step: across a circle (a
//    tube seen side on) the largest step is at most 2.41 times the one before it, at any
//    radius in pixels, so a tube's own curvature never fires, where a Sobel of the normals
//    fires at the rim of every thin tube; a crease turns in one step with none beside it (and
//    has surface beside it: a tube two pixels across has only the one step);
//  - depth: the second difference of inverse linear depth along rows, columns and diagonals.
//    Inverse depth is affine in screen space over any plane, so a flat surface gives exactly
//    zero whatever its slope (a Sobel of raw depth would flag every tilted plane); a depth
//    break gives a large negative value on its near side. The background counts as infinitely
//    far (inverse depth 0), so silhouettes against it are depth breaks too. Strands of one
//    clump (all three pixels) make no depth break: a clump is outlined as one.
// Out: 0 where there is no line, else the line's half width in pixels there (EDGE_RADII: from
// u_world_width at this pixel's depth, clamped to [0.5, u_max_radius]; else 1).
#include "gbuffer/layout.glsl"

uniform sampler2D u_linear_depth;
uniform sampler2D u_normal_exponent_id;
uniform float u_depth_threshold;   // relative second difference of inverse depth
uniform float u_crease_cosine;     // cos(crease angle)
uniform bool u_ids;                // use surface ids
#ifdef STRAND_IDS
uniform sampler2D u_strand_id;     // G-buffer datum strand_id: (strand, clump), 0 none
#endif
#ifdef EDGE_RADII
uniform float u_world_width;       // the line's width in view-space units
uniform float u_max_radius;        // pixels
uniform mat4 u_projection;
#endif

out float out_edge;

const float CURVE_RATIO = 3.0;

ivec2 g_size;

float depth_at(ivec2 p) {
    return texelFetch(u_linear_depth, clamp(p, ivec2(0), g_size - 1), 0).r;
}

vec4 normal_id_at(ivec2 p) {
    return texelFetch(u_normal_exponent_id, clamp(p, ivec2(0), g_size - 1), 0);
}

#ifdef STRAND_IDS
vec2 strand_at(ivec2 p) {
    return texelFetch(u_strand_id, clamp(p, ivec2(0), g_size - 1), 0).rg;
}
#endif

// What a crease test needs of a pixel: covered, its surface (and strand), its normal.
struct Sample {
    bool covered;
    float id;
    float strand;
    vec3 normal;
    float depth;
};

Sample sample_of(ivec2 p, float depth, vec4 normal_id, vec2 strand) {
    Sample s;
    bool inside = all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, g_size));
    s.depth = depth;
    s.covered = inside && depth > 0.0;
    s.id = normal_id.w;
    s.normal = octahedral_decode(normal_id.xy);
    s.strand = strand.r;
    return s;
}

Sample sample_at(ivec2 p) {
#ifdef STRAND_IDS
    vec2 strand = strand_at(p);
#else
    vec2 strand = vec2(0.0);
#endif
    return sample_of(p, depth_at(p), normal_id_at(p), strand);
}

bool one_surface(Sample a, Sample b) {
    return a.covered && b.covered && same_surface(a.id, b.id) && abs(a.strand - b.strand) < 0.5;
}

float turn(Sample a, Sample b) {
    return acos(clamp(dot(a.normal, b.normal), -1.0, 1.0));
}

// The 3x3 neighbourhood's index of the offset o (each of x, y in -1..1).
int at3(ivec2 o) {
    return (o.y + 1) * 3 + o.x + 1;
}

void main() {
    g_size = textureSize(u_linear_depth, 0);
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = depth_at(p);
    if (d <= 0.0) {  // background: lines belong to the surfaces
        out_edge = 0.0;
        return;
    }
    // The 3x3 neighbourhood's depths and strands and the 4-neighbours' normals and ids, each
    // fetched once for the three tests below (clamped to the image, as depth_at has them).
    float depths[9];
    vec2 strands[9];
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            ivec2 o = ivec2(x, y);
            depths[at3(o)] = depth_at(p + o);
#ifdef STRAND_IDS
            strands[at3(o)] = strand_at(p + o);
#else
            strands[at3(o)] = vec2(0.0);
#endif
        }
    }
    const ivec2 sides[4] = ivec2[](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    Sample here = sample_of(p, d, normal_id_at(p), strands[4]);
    Sample around[4];  // around[k ^ 1] is opposite around[k]
    for (int k = 0; k < 4; ++k) {
        around[k] = sample_of(p + sides[k], depths[at3(sides[k])], normal_id_at(p + sides[k]),
                              strands[at3(sides[k])]);
    }
    float id = here.id;
    float edge = 0.0;

    // Ids: a different surface (or clump) beside this one, farther away or background.
    if (u_ids) {
        for (int k = 0; k < 4; ++k) {
            float other_depth = around[k].depth;
            bool other = !same_surface(around[k].id, id);
#ifdef STRAND_IDS
            // another clump of the same surface (cartoon hair: one colour, many clumps)
            other = other || abs(strands[at3(sides[k])].g - strands[4].g) > 0.5;
#endif
            if (other && (other_depth <= 0.0 || other_depth > d)) edge = 1.0;
        }
    }

    // Creases: one large turn of the normal between this pixel and a neighbour no farther
    // away (the near side; ties to the right and up), with no comparable turn either side.
    for (int k = 0; k < 4; ++k) {
        Sample next = around[k];
        if (!one_surface(here, next) || dot(here.normal, next.normal) >= u_crease_cosine) continue;
        bool near_side = d < next.depth || (d == next.depth && k % 2 == 0);
        if (!near_side) continue;
        float step_turn = turn(here, next);
        Sample before = around[k ^ 1];
        Sample after = sample_at(p + 2 * sides[k]);
        // a crease has surface beside it to compare with: a tube one or two pixels across,
        // whose normal turns by up to 90 degrees a pixel, has none
        bool has_before = one_surface(before, here);
        bool has_after = one_surface(next, after);
        bool crease = has_before || has_after;
        if (has_before) crease = crease && step_turn > CURVE_RATIO * turn(before, here);
        if (has_after) crease = crease && step_turn > CURVE_RATIO * turn(next, after);
        if (crease) edge = 1.0;
    }

    // Depth breaks: second differences of inverse depth, near side only; not between strands
    // of one clump (a clump is outlined as one).
    const ivec2 axes[4] = ivec2[](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    for (int k = 0; k < 4; ++k) {
#ifdef STRAND_IDS
        float clump_here = strands[4].g;
        if (clump_here > 0.5 && abs(strands[at3(axes[k])].g - clump_here) < 0.5 &&
                abs(strands[at3(-axes[k])].g - clump_here) < 0.5) continue;
#endif
        float a = depths[at3(axes[k])];
        float b = depths[at3(-axes[k])];
        float inverse_a = a > 0.0 ? 1.0 / a : 0.0;
        float inverse_b = b > 0.0 ? 1.0 / b : 0.0;
        float second = (inverse_a + inverse_b - 2.0 / d) * d;
        if (second < -u_depth_threshold) edge = 1.0;
    }
#ifdef EDGE_RADII
    // the projection's y scale: pixels a view unit at depth d (or at any depth, orthographic)
    bool orthographic = u_projection[3][3] > 0.5;
    float pixels_per_unit = 0.5 * float(g_size.y) * u_projection[1][1] / (orthographic ? 1.0 : d);
    edge *= clamp(0.5 * u_world_width * pixels_per_unit, 0.5, u_max_radius);
#endif
    out_edge = edge;
}
