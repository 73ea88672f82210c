// Stipple patterns (Revie 2.3.4, Listing 2.6, Figure 2.14), in GL pixel coordinates. Each
// stipple user takes its own parity class (STIPPLE_PARITY), so several interleave (2.3.4); every
// user's class moves by the same shift per tile and sample (u_sample_index, set by the
// framework: 0 on a single frame, the sample since a temporal effect's history started, or
// render_samples' index), so over four samples the 1-in-4 pattern covers every pixel of its 2x2
// tile and an average (taa, accumulated samples) integrates it while the users still interleave:
//   STIPPLE_PATTERN 4: one in four, one pixel of every 2x2 tile;
//   STIPPLE_PATTERN 2: one in two, one diagonal of every 2x2 tile.
#ifndef STIPPLE_PATTERN
#define STIPPLE_PATTERN 4
#endif
#ifndef STIPPLE_PARITY
#define STIPPLE_PARITY ivec2(0, 0)
#endif

uniform int u_sample_index;

// Which pixel of its 2x2 tile a class takes is decorrelated from the screen: tile (x, y) takes
// the shift x + 2y + 2 (f(x) + g(y)) + sample (mod 4, in SHIFTS' order), f and g a random bit
// per column and per row of tiles. Listing 2.6's grid, the same pixel in every tile, puts all
// of the pattern's error at the frequencies of the 2x2 tile, a dot grid fixed to the screen
// that taa could not tell from the image; here each tile row runs through the four pixels
// and the rows and columns are flipped at random, so the pattern has no energy there (its
// parities balance) and no period of its own. Two samples are never side by side (the
// steps between neighbouring tiles: 1 or 3 along a row, 0 or 2 along a column), so the
// obliteration always has the pixels either side of a sample; over any four samples every
// tile takes each of its pixels once, and every user's class moves by the same shift, so the
// users still interleave (2.3.4).
uint stipple_hash(uint v) {  // integer mixing (a PCG step, Jarzynski and Olano 2020)
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The parity class of `pixel`'s tile for this sample: STIPPLE_PARITY XOR the tile's shift.
ivec2 stipple_parity_at(ivec2 pixel) {
    const ivec2 SHIFTS[4] = ivec2[](ivec2(0, 0), ivec2(1, 1), ivec2(1, 0), ivec2(0, 1));
    ivec2 tile = pixel >> 1;
    int flips = int((stipple_hash(uint(tile.x)) & 1u) +
                    (stipple_hash(uint(tile.y) ^ 0x9e3779b9u) & 1u));
    ivec2 shift = SHIFTS[(u_sample_index + tile.x + 2 * tile.y + 2 * flips) & 3];
    return (STIPPLE_PARITY ^ shift) & 1;
}

bool stipple_sample(ivec2 pixel) {
    ivec2 q = (pixel ^ stipple_parity_at(pixel)) & 1;
#if STIPPLE_PATTERN == 2
    return q.x == q.y;
#else
    return q.x == 0 && q.y == 0;
#endif
}

// The stipple pixel of the tile containing `pixel` (the sample a material reads back).
ivec2 stipple_pixel_of(ivec2 pixel) {
#if STIPPLE_PATTERN == 2
    return stipple_sample(pixel) ? pixel : pixel ^ ivec2(1, 0);  // the other of its row
#else
    return (pixel & ~1) | stipple_parity_at(pixel);
#endif
}

// stipple_pixel_of for a pixel that may lie left of or below the frame (a point off-screen):
// the tile's sample is off-screen too; the next one of the class 2 pixels on stands in.
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
