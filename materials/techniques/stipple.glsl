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

// Which pixel of each 2x2 tile a class takes is decorrelated from the screen: every tile XORs
// the class with its own shift, a hash of the tile and of the block of four samples (a per-tile
// permutation of the tile's pixels, drawn again every four samples). A fixed grid (Listing 2.6)
// has all its error at the frequencies of the 2x2 tile, where it stays on the screen as the
// image moves (the crawl) and beats with taa's 4-sample cycle; per tile the error is noise that
// an average resolves. Within a block of four samples the tile's shifts are the four
// different ones, so four samples still cover every pixel of the tile, and since every user's
// class moves by the same shift, the users still interleave.
uint stipple_hash(uvec3 v) {  // integer mixing (Jarzynski and Olano's PCG3D)
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    return v.x;
}

// The parity class of `pixel`'s tile for this sample: STIPPLE_PARITY XOR the tile's shift.
ivec2 stipple_parity_at(ivec2 pixel) {
    const ivec2 SHIFTS[4] = ivec2[](ivec2(0, 0), ivec2(1, 1), ivec2(1, 0), ivec2(0, 1));
    uint h = stipple_hash(uvec3(ivec3(pixel >> 1, u_sample_index >> 2)));
    ivec2 shift = SHIFTS[(u_sample_index + int(h & 3u)) & 3] ^ SHIFTS[int((h >> 2) & 3u)];
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
