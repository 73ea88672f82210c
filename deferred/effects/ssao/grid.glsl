// The reduced grid SSAO may run on: a texel's sample point is the full-resolution pixel under
// its centre (its depth and normal are the G-buffer's there, not an average across an edge).
// ratio = full-resolution size / grid size, per axis.
ivec2 ssao_sample_pixel(ivec2 texel, vec2 ratio) {
    return ivec2(floor((vec2(texel) + 0.5) * ratio));
}
