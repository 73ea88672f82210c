// Stipple patterns (Revie 2.3.4, Listing 2.6, Figure 2.14), in GL pixel coordinates. Each
// stipple user takes its own parity class (STIPPLE_PARITY), so several interleave (2.3.4); every
// user's class moves by the same shift per sample (u_sample_index, set by the framework: 0 on a
// single frame, the sample since a temporal effect's history started, or render_samples' index),
// so over four samples the 1-in-4 pattern covers every pixel of its 2x2 tile and an average
// (taa, accumulated samples) integrates it while the users still interleave:
//   STIPPLE_PATTERN 4: one in four, the pixel at STIPPLE_PARITY of every 2x2 tile;
//   STIPPLE_PATTERN 2: one in two, the checkerboard whose x + y has the parity of
//                      STIPPLE_PARITY.x + STIPPLE_PARITY.y.
#ifndef STIPPLE_PATTERN
#define STIPPLE_PATTERN 4
#endif
#ifndef STIPPLE_PARITY
#define STIPPLE_PARITY ivec2(0, 0)
#endif

uniform int u_sample_index;

// The parity class of this sample: STIPPLE_PARITY shifted by (0, 0), (1, 1), (1, 0), (0, 1)
// in turn (the diagonal first, so two samples cover both checkerboards of the 1-in-2 pattern).
ivec2 stipple_parity() {
    const ivec2 SHIFTS[4] = ivec2[](ivec2(0, 0), ivec2(1, 1), ivec2(1, 0), ivec2(0, 1));
    return (STIPPLE_PARITY + SHIFTS[u_sample_index & 3]) & 1;
}

bool stipple_sample(ivec2 pixel) {
    ivec2 q = pixel - stipple_parity();
#if STIPPLE_PATTERN == 2
    return ((q.x + q.y) & 1) == 0;
#else
    return (q.x & 1) == 0 && (q.y & 1) == 0;
#endif
}

// The stipple pixel of the tile containing `pixel` (the sample a material reads back).
ivec2 stipple_pixel_of(ivec2 pixel) {
#if STIPPLE_PATTERN == 2
    return stipple_sample(pixel) ? pixel : pixel - ivec2(1, 0);
#else
    ivec2 parity = stipple_parity();
    return ((pixel - parity) & ~1) + parity;
#endif
}

// stipple_pixel_of, stepped into the frame: at the left or bottom border a parity class other
// than (0, 0) has its tile's sample at -1; the next sample of the class is 2 pixels on.
ivec2 stipple_pixel_in(ivec2 pixel) {
    ivec2 sample_pixel = stipple_pixel_of(pixel);
    return sample_pixel + 2 * ivec2(lessThan(sample_pixel, ivec2(0)));
}

// Window-space depth of a linear view depth (the inverse of what the G-buffer stores).
float window_depth(float linear_depth, mat4 projection) {
    if (linear_depth <= 0.0) return 1.0;  // background
    float z = -linear_depth;
    float ndc = (projection[2][2] * z + projection[3][2]) / -z;
    return clamp(ndc * 0.5 + 0.5, 0.0, 1.0);
}
