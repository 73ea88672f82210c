// Stipple patterns (Revie 2.3.4, Listing 2.6, Figure 2.14), in GL pixel coordinates.
//   STIPPLE_PATTERN 4: one in four, the (even, even) pixel of every 2x2 tile;
//   STIPPLE_PATTERN 2: one in two, a checkerboard.
#ifndef STIPPLE_PATTERN
#define STIPPLE_PATTERN 4
#endif

bool stipple_sample(ivec2 pixel) {
#if STIPPLE_PATTERN == 2
    return ((pixel.x + pixel.y) & 1) == 0;
#else
    return (pixel.x & 1) == 0 && (pixel.y & 1) == 0;
#endif
}

// The stipple pixel of the tile containing `pixel` (the sample a material reads back).
ivec2 stipple_pixel_of(ivec2 pixel) {
#if STIPPLE_PATTERN == 2
    return ((pixel.x + pixel.y) & 1) == 0 ? pixel : pixel - ivec2(1, 0);
#else
    return pixel & ~1;
#endif
}

// A pixel next to a stipple sample that holds the scene the stipple sits on.
ivec2 stipple_neighbour(ivec2 pixel, ivec2 size) {
    return ivec2(pixel.x + 1 < size.x ? pixel.x + 1 : pixel.x - 1, pixel.y);
}

// Window-space depth of a linear view depth (the inverse of what the G-buffer stores).
float window_depth(float linear_depth, mat4 projection) {
    if (linear_depth <= 0.0) return 1.0;  // background
    float z = -linear_depth;
    float ndc = (projection[2][2] * z + projection[3][2]) / -z;
    return clamp(ndc * 0.5 + 0.5, 0.0, 1.0);
}
