// Screen-space ambient occlusion over the clean G-buffer (screen phase: before any stipple
// pass, Revie 2.4.2), on every pixel or, with REDUCED_GRID, on a coarser grid whose texels
// sample the G-buffer at their sample points (effects/ssao/grid.glsl) and keep that point's
// depth beside the occlusion for the depth-aware blur and upsample.
#include "gbuffer/layout.glsl"
#include "effects/ssao/occlusion.glsl"

#ifdef REDUCED_GRID
#include "effects/ssao/grid.glsl"

uniform vec2 u_grid_size;

out vec2 out_occlusion_depth;

void main() {
    ivec2 pixel = ssao_sample_pixel(ivec2(gl_FragCoord.xy), u_resolution / u_grid_size);
    float depth = texelFetch(u_linear_depth, pixel, 0).r;
    float open = depth > 0.0 ? ssao_occlusion(vec2(pixel) + 0.5, pixel, depth, gl_FragCoord.xy)
                             : 1.0;
    out_occlusion_depth = vec2(open, depth);
}
#else
out float out_occlusion;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(u_linear_depth, pixel, 0).r;
    if (depth <= 0.0) {
        out_occlusion = 1.0;
        return;
    }
    out_occlusion = ssao_occlusion(gl_FragCoord.xy, pixel, depth, gl_FragCoord.xy);
}
#endif
