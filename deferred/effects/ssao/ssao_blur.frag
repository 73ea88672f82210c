// Depth-aware box blur of the raw SSAO, 5x5 or (2 BLUR_RADIUS + 1)^2 texels (hides the
// per-pixel rotation noise). With REDUCED_GRID the raw target holds each texel's sample-point
// depth beside its occlusion, and the blur keeps it there for the upsample.
uniform sampler2D u_ssao_raw;

#ifndef BLUR_RADIUS
#define BLUR_RADIUS 2
#endif

#ifdef REDUCED_GRID
#define DEPTH_AT(q) texelFetch(u_ssao_raw, q, 0).g
out vec2 out_occlusion_depth;
#else
uniform sampler2D u_linear_depth;
#define DEPTH_AT(q) texelFetch(u_linear_depth, q, 0).r
out float out_occlusion;
#endif

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_ssao_raw, 0);
    float depth = DEPTH_AT(pixel);
    float total = 0.0;
    float weight = 0.0;
    for (int y = -BLUR_RADIUS; y <= BLUR_RADIUS; ++y) {
        for (int x = -BLUR_RADIUS; x <= BLUR_RADIUS; ++x) {
            ivec2 q = clamp(pixel + ivec2(x, y), ivec2(0), size - 1);
            float w = abs(DEPTH_AT(q) - depth) < 0.05 * depth + 1e-4 ? 1.0 : 0.0;
            total += texelFetch(u_ssao_raw, q, 0).r * w;
            weight += w;
        }
    }
    float open = weight > 0.0 ? total / weight : 1.0;
#ifdef REDUCED_GRID
    out_occlusion_depth = vec2(open, depth);
#else
    out_occlusion = open;
#endif
}
