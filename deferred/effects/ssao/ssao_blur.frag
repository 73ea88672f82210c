// 5x5 depth-aware box blur of the raw SSAO (hides the per-pixel rotation noise).
uniform sampler2D u_ssao_raw;
uniform sampler2D u_linear_depth;

out float out_occlusion;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_ssao_raw, 0);
    float depth = texelFetch(u_linear_depth, pixel, 0).r;
    float total = 0.0;
    float weight = 0.0;
    for (int y = -2; y <= 2; ++y) {
        for (int x = -2; x <= 2; ++x) {
            ivec2 q = clamp(pixel + ivec2(x, y), ivec2(0), size - 1);
            float w = abs(texelFetch(u_linear_depth, q, 0).r - depth) < 0.05 * depth + 1e-4
                      ? 1.0 : 0.0;
            total += texelFetch(u_ssao_raw, q, 0).r * w;
            weight += w;
        }
    }
    out_occlusion = weight > 0.0 ? total / weight : 1.0;
}
