// Stipple obliteration (Revie 2.4.4, Figure 2.19): drawn with the stippled mesh; where this
// mesh's stipple sample sits, a neighbouring pixel's composition (from the snapshot taken after
// the materials' own opaque passes) and depth replace it, leaving the scene the stipple covered.
//
// The neighbour must show the surface the sample covered, not an occluder beside it: among the
// pixels around the sample (the 8 of its 3x3 block for the 1-in-4 pattern, the 4 edge-adjacent
// for 1-in-2, those outside this pattern) those nearer than the sample are out (an occluder edge
// stays straight), and of the rest one of an opposite pair showing the same surface, else the
// one whose surface (id and depth) most others share.
#include "materials/techniques/stipple.glsl"
#include "gbuffer/layout.glsl"

uniform sampler2D u_composite_snapshot;
uniform sampler2D u_linear_depth;
uniform sampler2D u_normal_exponent_id;
uniform float u_surface_id;
uniform vec2 u_resolution;
uniform mat4 u_projection;

in vec3 v_position;
out vec4 out_color;

#if STIPPLE_PATTERN == 2
const int CANDIDATES = 4;
#else
const int CANDIDATES = 8;
#endif
const ivec2 OFFSETS[8] = ivec2[](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1),
                                 ivec2(1, 1), ivec2(-1, 1), ivec2(1, -1), ivec2(-1, -1));

bool same_depth(float a, float b) {
    return abs(a - b) <= 0.02 * max(a, b) + 1e-4;  // background (0) matches only background
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    if (!stipple_sample(pixel)) discard;
    // Ours only if the G-buffer holds this very surface: same material, same depth.
    float depth = texelFetch(u_linear_depth, pixel, 0).r;
    if (!same_surface(texelFetch(u_normal_exponent_id, pixel, 0).w, u_surface_id)) discard;
    if (abs(depth + v_position.z) > 1e-3 * depth + 1e-5) discard;

    float ids[8];
    float depths[8];
    bool valid[8];
    ivec2 size = ivec2(u_resolution);
    for (int k = 0; k < CANDIDATES; ++k) {
        ivec2 q = pixel + OFFSETS[k];
        // a neighbour that is a sample of the pattern too (tiles choose their pixel apart)
        // holds what this pass erases
        valid[k] = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size)) &&
                   !stipple_sample(q);
        ids[k] = 0.0;
        depths[k] = 0.0;
        if (!valid[k]) continue;
        depths[k] = texelFetch(u_linear_depth, q, 0).r;
        ids[k] = texelFetch(u_normal_exponent_id, q, 0).w;
        // behind the sample (or background): what the stipple may have covered
        valid[k] = depths[k] <= 0.0 || depths[k] >= depth * (1.0 - 1e-3);
    }
    // The surface the sample covered most likely runs on through the pixel: where the two
    // neighbours of an opposite pair (left and right, above and below, a diagonal) show the
    // same surface (id, and depth within 10% - a surface at a grazing angle, the floor
    // toward the horizon, changes depth quickly from row to row), it is one of those; of
    // such pairs, and failing any of the candidates, the surface most others share (its id
    // and depth) wins. By votes alone, the sky above a floor pixel beside a silhouette
    // (three pixels that all agree) won over the floor to its left and right: a dot of sky.
    int best = -1;
    int best_votes = 0;
    bool best_paired = false;
    for (int k = 0; k < CANDIDATES; ++k) {
        if (!valid[k]) continue;
        int opposite = k < 4 ? k ^ 1 : 11 - k;  // OFFSETS' order: pairs (0 1) (2 3) (4 7) (5 6)
        bool paired = valid[opposite] && same_surface(ids[opposite], ids[k]) &&
                      abs(depths[opposite] - depths[k]) <= 0.1 * max(depths[opposite], depths[k]);
        int votes = 0;
        for (int j = 0; j < CANDIDATES; ++j) {
            if (valid[j] && same_surface(ids[j], ids[k]) && same_depth(depths[j], depths[k]))
                votes += 1;
        }
        if ((paired && !best_paired) || (paired == best_paired && votes > best_votes)) {
            best = k;
            best_votes = votes;
            best_paired = paired;
        }
    }
    ivec2 source = best >= 0 ? pixel + OFFSETS[best]
                             : clamp(pixel + ivec2(1, 0), ivec2(0), size - 1);
    if (best_paired) {
        // between the two: the surface's colour and depth interpolated across the pixel (one
        // neighbour's depth at a grazing silhouette is off by the fur's whole thickness, and
        // the shells failed the depth test over the dark root shell: a dark dot)
        ivec2 other = pixel + OFFSETS[best < 4 ? best ^ 1 : 11 - best];
        out_color = 0.5 * (texelFetch(u_composite_snapshot, source, 0) +
                           texelFetch(u_composite_snapshot, other, 0));
        gl_FragDepth = window_depth(0.5 * (depths[best] + depths[best < 4 ? best ^ 1 : 11 - best]),
                                    u_projection);
        return;
    }
    out_color = texelFetch(u_composite_snapshot, source, 0);
    gl_FragDepth = window_depth(texelFetch(u_linear_depth, source, 0).r, u_projection);
}
