// Post: fast approximate anti-aliasing, after Lottes' FXAA 3.11 "quality" algorithm: where the
// local luma contrast is high, find the edge's orientation, walk along it both ways to its ends,
// and resample the frame across the edge by how far the pixel is from the nearer end; blend
// isolated single-pixel features by their contrast with the 3x3 average (sub-pixel aliasing).
// Runs on the tone-mapped, sRGB-encoded frame (a copy of `final`), as FXAA expects.
uniform sampler2D u_source;
uniform float u_edge_threshold;      // contrast needed, relative to the local maximum luma
uniform float u_edge_threshold_min;  // contrast needed in dark areas
uniform float u_subpixel;            // strength of the sub-pixel blend (0 = off)

out vec4 out_color;

const int SEARCH_STEPS = 10;
const float STEP_SIZES[SEARCH_STEPS] = float[](1.0, 1.0, 1.0, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0,
                                               4.0);

vec3 fetch(ivec2 pixel) {
    return texelFetch(u_source, clamp(pixel, ivec2(0), textureSize(u_source, 0) - 1), 0).rgb;
}

// Bilinear read at a position in pixels (pixel centres at .5), without relying on the
// target's filter state.
vec3 bilinear(vec2 position) {
    vec2 p = position - 0.5;
    ivec2 i = ivec2(floor(p));
    vec2 f = p - floor(p);
    return mix(mix(fetch(i), fetch(i + ivec2(1, 0)), f.x),
               mix(fetch(i + ivec2(0, 1)), fetch(i + ivec2(1, 1)), f.x), f.y);
}

float luma(vec3 c) {
    return dot(c, vec3(0.299, 0.587, 0.114));
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 centre = fetch(p);
    float lc = luma(centre);
    float ln = luma(fetch(p + ivec2(0, 1)));
    float ls = luma(fetch(p + ivec2(0, -1)));
    float le = luma(fetch(p + ivec2(1, 0)));
    float lw = luma(fetch(p + ivec2(-1, 0)));
    float lmax = max(lc, max(max(ln, ls), max(le, lw)));
    float lmin = min(lc, min(min(ln, ls), min(le, lw)));
    float range = lmax - lmin;
    if (range < max(u_edge_threshold_min, lmax * u_edge_threshold)) {
        out_color = vec4(centre, 1.0);
        return;
    }
    float lne = luma(fetch(p + ivec2(1, 1)));
    float lnw = luma(fetch(p + ivec2(-1, 1)));
    float lse = luma(fetch(p + ivec2(1, -1)));
    float lsw = luma(fetch(p + ivec2(-1, -1)));

    // Sub-pixel aliasing: how much the centre stands out from its neighbourhood.
    float average = (2.0 * (ln + ls + le + lw) + (lne + lnw + lse + lsw)) / 12.0;
    float subpixel = smoothstep(0.0, 1.0, clamp(abs(average - lc) / range, 0.0, 1.0));
    subpixel = subpixel * subpixel * u_subpixel;

    // Orientation: second differences across rows (a horizontal edge) and across columns.
    float horizontal = abs(lnw + lsw - 2.0 * lw) + 2.0 * abs(ln + ls - 2.0 * lc)
                     + abs(lne + lse - 2.0 * le);
    float vertical = abs(lnw + lne - 2.0 * ln) + 2.0 * abs(lw + le - 2.0 * lc)
                   + abs(lsw + lse - 2.0 * ls);
    bool is_horizontal = horizontal >= vertical;
    float l_negative = is_horizontal ? ls : lw;
    float l_positive = is_horizontal ? ln : le;
    float g_negative = abs(l_negative - lc);
    float g_positive = abs(l_positive - lc);
    vec2 across = is_horizontal ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
    vec2 along = is_horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0);
    float local_average;
    if (g_negative >= g_positive) {
        across = -across;
        local_average = 0.5 * (l_negative + lc);
    } else {
        local_average = 0.5 * (l_positive + lc);
    }
    float gradient = 0.25 * max(g_negative, g_positive);

    // Walk along the edge (between the centre and its steeper neighbour) to both ends.
    vec2 position = gl_FragCoord.xy;
    vec2 on_edge = position + 0.5 * across;
    vec2 end_a = on_edge - along;
    vec2 end_b = on_edge + along;
    float delta_a = luma(bilinear(end_a)) - local_average;
    float delta_b = luma(bilinear(end_b)) - local_average;
    bool done_a = abs(delta_a) >= gradient;
    bool done_b = abs(delta_b) >= gradient;
    for (int k = 1; k < SEARCH_STEPS && !(done_a && done_b); ++k) {
        if (!done_a) {
            end_a -= along * STEP_SIZES[k];
            delta_a = luma(bilinear(end_a)) - local_average;
            done_a = abs(delta_a) >= gradient;
        }
        if (!done_b) {
            end_b += along * STEP_SIZES[k];
            delta_b = luma(bilinear(end_b)) - local_average;
            done_b = abs(delta_b) >= gradient;
        }
    }
    float distance_a = dot(position - end_a, along);
    float distance_b = dot(end_b - position, along);
    bool nearer_a = distance_a < distance_b;
    float edge_offset = 0.5 - min(distance_a, distance_b) / (distance_a + distance_b);
    // Only move toward the edge if the luma at the nearer end changes the way the centre does.
    bool centre_darker = lc < local_average;
    bool consistent = ((nearer_a ? delta_a : delta_b) < 0.0) != centre_darker;
    float offset = max(consistent ? edge_offset : 0.0, subpixel);
    out_color = vec4(bilinear(position + across * offset), 1.0);
}
