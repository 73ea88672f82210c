// Exact mode, second half: a pixel's list sorted by depth (its GLASS_LAYERS nearest layers
// kept: a bounded layer count) and composed front to back over what lies behind, read
// through the sum of the layers' refraction offsets.
#include "materials/glass/lists.glsl"

uniform sampler2D u_glass_background;

in vec2 v_uv;
out vec4 out_color;

vec2 screen_offset(vec2 offset) {
    vec2 size = vec2(textureSize(u_glass_background, 0));
    return offset * vec2(size.y / size.x, 1.0);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 behind = texelFetch(u_glass_background, pixel, 0);
    uint node = glass_heads[pixel.y * u_glass_width + pixel.x];
    if (node == GLASS_NONE) {
        out_color = behind;
        return;
    }
    // the nearest GLASS_LAYERS layers, nearest first (insertion into sorted arrays)
    float depths[GLASS_LAYERS];
    vec3 emitted[GLASS_LAYERS];
    vec3 coverage[GLASS_LAYERS];
    int count = 0;
    vec2 offset = vec2(0.0);
    for (int guard = 0; node != GLASS_NONE && guard < (1 << 20); ++guard) {
        uvec4 layer = glass_layers[node - 1u];
        uvec2 link = glass_links[node - 1u];
        float depth = uintBitsToFloat(layer.w);
        offset += unpackHalf2x16(link.x);
        node = link.y;
        if (count == GLASS_LAYERS && depth >= depths[GLASS_LAYERS - 1]) continue;
        int k = min(count, GLASS_LAYERS - 1);
        for (; k > 0 && depths[k - 1] > depth; --k) {
            depths[k] = depths[k - 1];
            emitted[k] = emitted[k - 1];
            coverage[k] = coverage[k - 1];
        }
        vec2 rg = unpackHalf2x16(layer.x);
        vec2 b_r = unpackHalf2x16(layer.y);
        depths[k] = depth;
        emitted[k] = vec3(rg, b_r.x);
        coverage[k] = vec3(b_r.y, unpackHalf2x16(layer.z));
        count = min(count + 1, GLASS_LAYERS);
    }
    vec3 light = vec3(0.0);
    vec3 revealed = vec3(1.0);
    for (int k = 0; k < count; ++k) {
        light += revealed * emitted[k];
        revealed *= 1.0 - coverage[k];
    }
    vec3 seen = texture(u_glass_background, v_uv + screen_offset(offset)).rgb;
    out_color = vec4(light + seen * revealed, behind.a);
}
