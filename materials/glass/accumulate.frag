// Weighted blended order-independent transparency (McGuire and Bavoil 2013), accumulation: each
// glass fragment adds its emitted light and its coverage, weighted by w(z, alpha) (their
// Eq. 7, scaled by 1/10: only ratios of weights matter, and half floats keep more layers of
// bright highlights), and multiplies the revealage by 1 - its coverage. Per channel, as a
// coloured glass covers each channel by its own amount (a single layer composes exactly).
// The targets' blend states: add, add, (zero, one - source colour), add.
#include "materials/glass/layer.glsl"

layout(location = 0) out vec4 out_accum;       // sum of emitted * w
layout(location = 1) out vec4 out_coverage;    // sum of coverage * w
layout(location = 2) out vec4 out_revealage;   // the product of 1 - coverage (blended)
layout(location = 3) out vec2 out_refraction;  // sum of offsets (each layer bends the view)

float glass_weight(float depth, float alpha) {
    float z = abs(depth);
    return alpha * clamp(1.0 / (1e-5 + pow(z / 5.0, 2.0) + pow(z / 200.0, 6.0)), 1e-3, 3e2);
}

void main() {
    GlassLayer g = glass_layer();
    float alpha = dot(g.coverage, vec3(1.0 / 3.0));
    float w = glass_weight(g.depth, alpha);
    out_accum = vec4(g.emitted * w, 0.0);
    out_coverage = vec4(g.coverage * w, 0.0);
    out_revealage = vec4(g.coverage, 0.0);
    out_refraction = g.offset;
}
