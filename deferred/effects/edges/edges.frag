// Screen: edges from the clean G-buffer (before any stipple, Revie 2.4.2), drawn on the near
// side of each discontinuity so a line is one pixel wide before dilation:
//  - normals: Sobel on the decoded view-space normal (creases);
//  - ids: a 4-neighbour of another surface id that lies farther away (silhouettes, material
//    boundaries), or of another strand where the scene's materials write strand_id;
//  - depth: the second difference of inverse linear depth along rows, columns and diagonals.
//    Inverse depth is affine in screen space over any plane, so a flat surface gives exactly
//    zero whatever its slope (a Sobel of raw depth would flag every tilted plane); a depth
//    break gives a large negative value on its near side. The background counts as infinitely
//    far (inverse depth 0), so silhouettes against it are depth breaks too.
#include "gbuffer/layout.glsl"

uniform sampler2D u_linear_depth;
uniform sampler2D u_normal_exponent_id;
uniform float u_depth_threshold;   // relative second difference of inverse depth
uniform float u_normal_threshold;  // normal change across the pixel (Sobel / 4)
uniform bool u_ids;                // use surface ids
#ifdef STRAND_IDS
uniform sampler2D u_strand_id;     // G-buffer datum strand_id: 1 + a strand's index, 0 none
#endif

out float out_edge;

ivec2 g_size;

float depth_at(ivec2 p) {
    return texelFetch(u_linear_depth, clamp(p, ivec2(0), g_size - 1), 0).r;
}

vec4 normal_id_at(ivec2 p) {
    return texelFetch(u_normal_exponent_id, clamp(p, ivec2(0), g_size - 1), 0);
}

#ifdef STRAND_IDS
float strand_at(ivec2 p) {
    return texelFetch(u_strand_id, clamp(p, ivec2(0), g_size - 1), 0).r;
}
#endif

void main() {
    g_size = textureSize(u_linear_depth, 0);
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = depth_at(p);
    if (d <= 0.0) {  // background: lines belong to the surfaces
        out_edge = 0.0;
        return;
    }
    float id = normal_id_at(p).w;
    float edge = 0.0;

    // Ids: a different surface beside this one, farther away or background.
    if (u_ids) {
        const ivec2 sides[4] = ivec2[](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
        for (int k = 0; k < 4; ++k) {
            float other_depth = depth_at(p + sides[k]);
            bool other = !same_surface(normal_id_at(p + sides[k]).w, id);
#ifdef STRAND_IDS
            // another strand of the same surface (cartoon hair: one colour, many strands)
            other = other || abs(strand_at(p + sides[k]) - strand_at(p)) > 0.5;
#endif
            if (other && (other_depth <= 0.0 || other_depth > d)) edge = 1.0;
        }
    }

    // Normals: Sobel over the 3x3 block, where all of it is surface.
    vec3 n[9];
    bool covered = true;
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            vec4 sample_value = normal_id_at(p + ivec2(x, y));
            covered = covered && depth_at(p + ivec2(x, y)) > 0.0;
            n[(y + 1) * 3 + (x + 1)] = octahedral_decode(sample_value.xy);
        }
    }
    if (covered) {
        vec3 gx = (n[2] + 2.0 * n[5] + n[8]) - (n[0] + 2.0 * n[3] + n[6]);
        vec3 gy = (n[6] + 2.0 * n[7] + n[8]) - (n[0] + 2.0 * n[1] + n[2]);
        if (sqrt(dot(gx, gx) + dot(gy, gy)) / 4.0 > u_normal_threshold) edge = 1.0;
    }

    // Depth breaks: second differences of inverse depth, near side only.
    const ivec2 axes[4] = ivec2[](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    for (int k = 0; k < 4; ++k) {
        float a = depth_at(p + axes[k]);
        float b = depth_at(p - axes[k]);
        float inverse_a = a > 0.0 ? 1.0 / a : 0.0;
        float inverse_b = b > 0.0 ? 1.0 / b : 0.0;
        float second = (inverse_a + inverse_b - 2.0 / d) * d;
        if (second < -u_depth_threshold) edge = 1.0;
    }
    out_edge = edge;
}
