// Fur clumping (Silva et al. 3.3, Eq. 5, Algorithm 2) in the fragment shader: texture
// coordinates of a wet layer fragment are displaced away from its clump's centre, so the fur it
// shows comes from nearer the rim and the strands seem to gather toward the centre with height.
//
// The wetness mask (materials/techniques/wetness.py): (R, G) clump centre, B radius (UV units),
// A wetness rho; sampled nearest (a centre is never interpolated).
//
// Eq. 5: d = ((1 - w) h + w (1 + ln(h) / ln N)) rho s (c_pixel - c_mask).
//  - The printed k = -ln N makes the log term 2 at the first layer (h = 1/N) and 1 at the tip,
//    the reverse of the straight term and of Fig. 9; with k = ln N it rises from 0 to 1 like the
//    straight term, bending in early (Fig. 9 c, d), which is what we use.
//  - The printed factor r_mask is read as measuring the offset in clump radii, where it cancels:
//    a clump gathers the same share of its radius whatever its size (Fig. 13). s, the
//    clump_strength, scales it: 1 gathers the tips of fully wet fur into half the radius.
// Algorithm 2 ignores a displaced coordinate that falls on dry fur; we also ignore one that
// falls in another clump: a texel whose centre is farther than the clump's radius (Algorithm 1
// merges a droplet into a clump exactly when their centres are that close). Without it
// neighbouring wet clumps run into each other and fur wet all over shows no clumps at all.

// u_wetness_mask is declared in wet.glsl
#include "materials/shell_fur/wet.glsl"
uniform float u_clump_shape;     // w
uniform float u_clump_strength;  // s
uniform float u_layers;          // N, the most layers (shells)
uniform vec2 u_mask_wrap;        // 1 where the mesh's UVs wrap around (u, v): distances go round

// a - b in UV units, the short way round wrapped axes.
vec2 uv_delta(vec2 a, vec2 b) {
    vec2 d = a - b;
    return d - u_mask_wrap * floor(d + 0.5);
}

// (1 - w) h + w (1 + ln(h) / ln N), h kept to the layers' range [1/N, 1].
float clump_profile(float h, float w, float layers) {
    float n = max(layers, 2.0);
    float hh = clamp(h, 1.0 / n, 1.0);
    return (1.0 - w) * hh + w * (1.0 + log(hh) / log(n));
}

// Eq. 5's scalar: d = clump_gain (c_pixel - c_mask).
float clump_gain(float h, vec4 mask, float w, float layers, float strength) {
    return clump_profile(h, w, layers) * mask.a * strength;
}

// Eq. 5 for a texel of the mask.
vec2 clump_displacement(float h, vec4 mask, vec2 c_pixel, float w, float layers, float strength) {
    return clump_gain(h, mask, w, layers, strength) * uv_delta(c_pixel, mask.rg);
}

// Algorithm 2 at texture coordinate `uv` and height h: the displacement d to add to the colour
// and fur coordinates, its gain (within a clump uv + d = uv + gain (uv - c), so lookups there
// change (1 + gain) times as fast as uv), and whether the fragment is kept (false: it belongs
// to another clump, or its displaced coordinate falls on dry fur or into another clump). Dry
// fragments keep their coordinates; beside wet fur (not in the paper) the dry fur's top is cut
// down to 1 - 0.6 of the wetness about it (fur_wetness_near), so a dry patch's border slopes
// into the clumps over a few texels instead of standing as a wall.
bool clump_fur(vec2 uv, float h, out vec2 d, out float gain) {
    d = vec2(0.0);
    gain = 0.0;
    vec4 mask = textureLod(u_wetness_mask, uv, 0.0);
    if (mask.a == 0.0) return h <= 1.0 - 0.6 * fur_wetness_near(uv);
    gain = clump_gain(h, mask, u_clump_shape, u_layers, u_clump_strength);
    vec2 from_centre = uv_delta(uv, mask.rg);
    d = gain * from_centre;
    if (length(from_centre) > mask.b) return false;                     // a different clump
    vec4 there = textureLod(u_wetness_mask, uv + d, 0.0);
    if (there.a == 0.0) return false;                                   // from a dry area
    if (length(uv_delta(there.rg, mask.rg)) > mask.b) return false;    // from another clump
    return true;
}
