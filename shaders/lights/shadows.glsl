// Shadow maps (deferred.lighting.shadows): every shadowed light's maps are tiles of one depth
// texture, the shadow atlas, read with hardware comparison (sampler2DShadow, bilinear: each
// lookup is a 2x2 PCF). A light's record holds its shadow slot in extra.w (0: no shadow);
// slot k is row k - 1 of u_shadow_records, an RGBA32F texture of SHADOW_RECORD_TEXELS texels a row:
//   0: projection (1 cascades, 2 perspective, 3 cube), tiles, filter (0 pcf, 1 soft), softness
//   1: depth bias, normal bias (texels), cascade blend band (fraction of a cascade), -
//   2: the cascades' far view depths
//   3: -
//   4 + 6 i .. 9 + 6 i, tile i: the view-space -> atlas (u, v, depth) matrix's columns, the
//      tile's rectangle in the atlas (u0, v0, u1, v1), a texel's world size (x; per unit of
//      distance from the light where y = 1: a perspective tile)
// Without SHADOWS (no light of the scene casts shadows) light_shadow is 1 and reads nothing.
#include "common/lighting.glsl"

#ifdef SHADOWS
uniform sampler2DShadow u_shadow_atlas;
uniform sampler2D u_shadow_records;
uniform mat3 u_shadow_world_from_view;  // the camera's rotation, view -> world (cube faces)
uniform float u_shadow_atlas_texel;     // 1 / the atlas's size

vec4 shadow_texel(int row, int texel) {
    return texelFetch(u_shadow_records, ivec2(texel, row), 0);
}

// A 16-tap Poisson disk in the unit circle (the soft filter).
const vec2 SHADOW_POISSON[16] = vec2[](
    vec2(-0.9420, -0.3991), vec2(0.9456, -0.7689), vec2(-0.0942, -0.9294),
    vec2(0.3450, 0.2939), vec2(-0.9159, 0.4577), vec2(-0.8154, -0.8791),
    vec2(-0.3828, 0.2768), vec2(0.9748, 0.7565), vec2(0.4432, -0.9751),
    vec2(0.5374, -0.4737), vec2(-0.2650, -0.4189), vec2(0.7920, 0.1909),
    vec2(-0.2419, 0.9971), vec2(-0.8141, 0.9144), vec2(0.1998, 0.7864),
    vec2(0.1438, -0.1410));

float shadow_compare(vec3 uvz, vec4 rect) {
    // kept half a texel inside the tile: bilinear comparison never reads a neighbour's texels
    vec2 margin = vec2(0.5 * u_shadow_atlas_texel);
    return texture(u_shadow_atlas, vec3(clamp(uvz.xy, rect.xy + margin, rect.zw - margin),
                                        uvz.z));
}

// The lit fraction of a point at atlas coordinates uvz in tile rect.
float shadow_filter(vec3 uvz, vec4 rect, vec4 header) {
    float t = u_shadow_atlas_texel;
    float lit = 0.0;
    if (header.z < 0.5) {  // pcf: 3x3 bilinear comparisons a texel apart (4x4 texels, tent)
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x)
                lit += shadow_compare(uvz + vec3(vec2(x, y) * t, 0.0), rect);
        return lit / 9.0;
    }
    for (int k = 0; k < 16; ++k)  // soft: the disk, radius header.w texels
        lit += shadow_compare(uvz + vec3(SHADOW_POISSON[k] * header.w * t, 0.0), rect);
    return lit / 16.0;
}

// One tile's lit fraction at view-space P (normal N, unit L toward the light, distance to it).
float shadow_tile(int row, int tile, vec4 header, vec4 biases, vec3 P, vec3 N, vec3 L,
                  float distance) {
    int base = 4 + 6 * tile;
    mat4 to_atlas = mat4(shadow_texel(row, base), shadow_texel(row, base + 1),
                         shadow_texel(row, base + 2), shadow_texel(row, base + 3));
    vec4 rect = shadow_texel(row, base + 4);
    vec4 size = shadow_texel(row, base + 5);
    float texel = size.x * (size.y > 0.5 ? distance : 1.0);  // a texel's world size at P
    // normal offset and depth bias along L, in texels. A filter reaching r texels from the
    // centre reads the receiver's own plane up to r sin / cos of the light's angle deeper: the
    // offset along N grows with the reach and with sin (it lifts the point by itself, which
    // the light sees as 1 / cos deeper), so the kernel stays above the surface it lies on.
    float grazing = sqrt(clamp(1.0 - dot(N, L) * dot(N, L), 0.0, 1.0));
    float reach = header.z < 0.5 ? 1.5 : header.w;
    vec3 Q = P + N * (biases.y * texel * (0.5 + reach * grazing)) + L * (biases.x * texel);
    vec4 clip = to_atlas * vec4(Q, 1.0);
    vec3 uvz = clip.xyz / clip.w;
    if (uvz.z >= 1.0) return 1.0;  // beyond the map's far plane
    return shadow_filter(uvz, rect, header);
}

// The fraction of a light reaching view-space P on a surface of normal N (1: lit, 0: shadow).
float light_shadow(LightRecord light, vec3 P, vec3 N, vec3 L) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return 1.0;
    int row = slot - 1;
    vec4 header = shadow_texel(row, 0);
    vec4 biases = shadow_texel(row, 1);
    int kind = int(header.x + 0.5);
    if (kind == 1) {  // cascades: the first whose far depth lies beyond P, blended at its end
        vec4 splits = shadow_texel(row, 2);
        float depth = -P.z;
        int count = int(header.y + 0.5);
        float near = 0.0;
        for (int i = 0; i < count; ++i) {
            float far = splits[i];
            if (depth <= far) {
                float lit = shadow_tile(row, i, header, biases, P, N, L, 1.0);
                float band = biases.z * (far - near);
                if (i + 1 < count && depth > far - band) {
                    float next = shadow_tile(row, i + 1, header, biases, P, N, L, 1.0);
                    lit = mix(lit, next, smoothstep(far - band, far, depth));
                }
                return lit;
            }
            near = far;
        }
        return 1.0;  // beyond the shadow distance
    }
    vec3 from_light = P - light.position.xyz;
    float distance = length(from_light);
    if (kind == 2) return shadow_tile(row, 0, header, biases, P, N, L, distance);
    // cube: the face of the direction's major axis (+X, -X, +Y, -Y, +Z, -Z)
    vec3 d = u_shadow_world_from_view * from_light;
    vec3 a = abs(d);
    int face = a.x >= a.y && a.x >= a.z ? (d.x >= 0.0 ? 0 : 1)
             : a.y >= a.z ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
    return shadow_tile(row, face, header, biases, P, N, L, distance);
}
#else
float light_shadow(LightRecord light, vec3 P, vec3 N, vec3 L) {
    return 1.0;
}
#endif
