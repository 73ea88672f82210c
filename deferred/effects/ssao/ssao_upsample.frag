// Bilateral upsampling of the reduced-grid SSAO into the full-resolution `ssao` target. Each
// pixel blends the 2x2 grid texels whose sample points surround it, by distance (bilinear
// between the sample points) and by how near each sample point's depth is to its own, so that
// the occlusion of one surface never crosses a depth edge onto another (no halo around
// silhouettes). Where none of the four lies on its surface (a sliver thinner than the grid),
// it takes the one nearest in depth: a wider search only there would still cost every pixel
// on llvmpipe, which runs both sides of a branch under a mask.
#include "effects/ssao/grid.glsl"

uniform sampler2D u_ssao_reduced;  // occlusion, the sample point's linear depth
uniform sampler2D u_linear_depth;

out float out_occlusion;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(u_linear_depth, pixel, 0).r;
    if (depth <= 0.0) {
        out_occlusion = 1.0;
        return;
    }
    ivec2 grid = textureSize(u_ssao_reduced, 0);
    vec2 ratio = vec2(textureSize(u_linear_depth, 0)) / vec2(grid);
    // the texel whose sample point is at or before the pixel's centre, per axis
    ivec2 first = ivec2(floor(gl_FragCoord.xy / ratio - 0.5));
    float tolerance = 0.05 * depth + 1e-4;  // the blur's test for the same surface
    float total = 0.0;
    float weight = 0.0;
    float nearest = 1.0;
    float nearest_gap = 3.0e38;
    for (int y = 0; y <= 1; ++y) {
        for (int x = 0; x <= 1; ++x) {
            ivec2 q = clamp(first + ivec2(x, y), ivec2(0), grid - 1);
            vec2 texel = texelFetch(u_ssao_reduced, q, 0).rg;
            float gap = abs(texel.g - depth);
            vec2 at = vec2(ssao_sample_pixel(q, ratio)) + 0.5;
            vec2 tent = max(1.0 - abs(gl_FragCoord.xy - at) / ratio, 0.0);
            float w = tent.x * tent.y * (1.0 - smoothstep(0.5 * tolerance, tolerance, gap));
            total += texel.r * w;
            weight += w;
            if (gap < nearest_gap) {
                nearest_gap = gap;
                nearest = texel.r;
            }
        }
    }
    out_occlusion = weight > 1.0e-3 ? total / weight : nearest;
}
