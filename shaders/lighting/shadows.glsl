// Shadow maps (deferred.lighting.shadows): every shadowed light's maps are tiles of one depth
// texture, the shadow atlas, read with hardware comparison (sampler2DShadow, bilinear: each
// lookup is a 2x2 PCF). A light's record holds its shadow slot in extra.w (0: no shadow);
// slot k is row k - 1 of the ShadowRecords uniform block, SHADOW_RECORD_TEXELS (40) vec4s a
// row, SHADOW_RECORD_ROWS rows (the scene's max_shadowed_lights):
//   0: projection (1 cascades, 2 perspective, 3 cube), tiles, filter (0 pcf, 1 soft, 2 pcss),
//      softness
//   1: depth bias, normal bias (texels), cascade blend band (fraction of a cascade), the
//      light's emitter radius (pcss: an area light's equivalent disc)
//   2: the cascades' far view depths
//   3: -
//   4 + 6 i .. 9 + 6 i, tile i: the view-space -> atlas (u, v, depth) matrix's columns, the
//      tile's rectangle in the atlas (u0, v0, u1, v1), a texel's world size (x; per unit of
//      distance from the light where y = 1: a perspective tile), the tile's near and far
//      distances (z, w: a depth back to the light's view depth)
// The light_shadow_* functions return the fraction of the light reaching a point per channel
// (a light's GLSL multiplies its radiance by it): grey from the depth maps, coloured where a
// transparent caster lies between (SHADOW_TRANSMITTANCE below). Without SHADOWS (no light of
// the scene casts shadows) they are 1 and read nothing.
//
// Transmittance maps (SHADOW_TRANSMITTANCE: a transparent caster such as glass draws them;
// deferred.lighting.shadows.transmittance): over the atlas's square its lights' maps take,
// texel for texel (atlas coordinates times u_transmittance_from_atlas),
// u_shadow_transmittance holds the product of the transparent casters' transmittances each
// texel sees and u_shadow_transparent_depth the depth of the nearest of them. A point beyond
// that depth takes the colour, filtered bilinearly.
//
// Percentage-closer soft shadows (SHADOW_PCSS: a light of the scene filters so; Fernando 2005)
// on perspective tiles: blockers are searched for over the part of the map the cone from the
// point to the light's disc crosses (u_shadow_depths: the atlas's raw depths), and the
// comparisons are filtered over the penumbra their mean depth gives, r (1 / z_blocker - 1 /
// z_receiver) / (2 tan(half the tile's angle)) of the tile for an emitter of radius r. Both
// reaches are capped at PCSS_MAX_REACH of the tile; the disk turns with the pixel (interleaved
// gradient noise, Jimenez 2014), so a wide penumbra is grain rather than bands.
//
// Deep opacity maps (OPACITY_SHADOWS: a volume such as fur draws them; Yuksel and Keyser 2008):
// over the atlas's square its lights' maps take (atlas coordinates times u_opacity_from_atlas),
// at a coarser resolution, u_opacity_first holds the light-view depths of the volume's front
// (R) and of its back (-G), and u_opacity four layers of optical depth (times the volume's
// density factor) accumulated from the front up to u_opacity_layers behind. A volume draws
// there its translucent part, and leaves it out of the depth atlas (deferred.api.ShadowView's
// opacity_maps), so each surface takes the volume's shadow from these maps once:
// - a receiver compiled with OPACITY_RECEIVER (the volume's own shading) multiplies each
//   shadowed light by the transmittance exp(-optical depth) at its depth, and takes
//   opacity_fallback (the volume's cheap stand-in, set before the lights are evaluated) for a
//   light without a shadow slot;
// - any other surface multiplies it by the transmittance through the whole volume where it
//   lies beyond the volume's back along the light, and by nothing where it lies inside: the
//   volume's own surfaces lit by the generic light passes (a deferred fur's skin, whose light
//   the shells read and scale by their own transmittance) keep their whole light. Where one
//   lies beyond the back (the skin under an open sheet of fur) it takes the whole
//   transmittance, and the deferred layer reading it finds that again through the same lookup
//   (opacity_as_light_pass) before it swaps the sample's light for its own.
#include "common/lighting.glsl"

#ifdef OPACITY_RECEIVER
float opacity_fallback = 1.0;  // a global: what an unshadowed light is multiplied by
// the first shadowed light's layers where the lights were evaluated, as 1 - transmittance to
// the ends of layers 1, 2 and 4 (the fur's opacity_shadow debug view); -1: none looked up
vec3 opacity_seen = vec3(-1.0);
// opacity_split: shadowed lights return their depth shadow alone and leave the transmittance in
// opacity_last (a deferred fur layer corrects the summed light it read by it, light by light)
bool opacity_split = false;
float opacity_last = 1.0;
// opacity_as_light_pass: shadowed lights return what the generic light passes' lookup gives
// at P (the depth shadow times opacity_beyond): a deferred fur layer's light at its sample as
// the light pass lit it, a sample that may lie beyond the volume's back (the skin under an
// open sheet of fur, whose front and back are its tips)
bool opacity_as_light_pass = false;
#endif

#ifdef OPACITY_RECEIVER
#define SHADOW_UNSHADOWED opacity_fallback
#else
#define SHADOW_UNSHADOWED 1.0
#endif

#ifdef SHADOWS
uniform sampler2DShadow u_shadow_atlas;
layout(std140) uniform ShadowRecords {
    vec4 shadow_record_data[SHADOW_RECORD_ROWS * SHADOW_RECORD_TEXELS];
};
uniform mat3 u_shadow_world_from_view;  // the camera's rotation, view -> world (cube faces)
uniform float u_shadow_atlas_texel;     // 1 / the atlas's size

vec4 shadow_texel(int row, int texel) {
    return shadow_record_data[row * SHADOW_RECORD_TEXELS + texel];
}

// The soft filter's 16-tap Poisson disk in the unit circle.
const vec2 SHADOW_POISSON[16] = vec2[](
    vec2(-0.9420, -0.3991), vec2(0.9456, -0.7689), vec2(-0.0942, -0.9294),
    vec2(0.3450, 0.2939), vec2(-0.9159, 0.4577), vec2(-0.8154, -0.8791),
    vec2(-0.3828, 0.2768), vec2(0.9748, 0.7565), vec2(0.4432, -0.9751),
    vec2(0.5374, -0.4737), vec2(-0.2650, -0.4189), vec2(0.7920, 0.1909),
    vec2(-0.2419, 0.9971), vec2(-0.8141, 0.9144), vec2(0.1998, 0.7864),
    vec2(0.1438, -0.1410));

#if defined(OPACITY_SHADOWS) || defined(SHADOW_PCSS) || defined(SURFACE_TRANSMISSION)
// The light-view depth of a depth-buffer value of a tile (near, far; perspective or not).
float shadow_view_depth(float window_z, vec4 size) {
    float n = size.z, f = size.w;
    if (size.y < 0.5) return n + window_z * (f - n);
    return 2.0 * n * f / (f + n - (2.0 * window_z - 1.0) * (f - n));
}
#endif

#ifdef SHADOW_TRANSMITTANCE
uniform sampler2D u_shadow_transmittance;      // RGBA8: product of the transmittances
uniform sampler2D u_shadow_transparent_depth;  // R32F: the nearest transparent caster's depth
uniform float u_transmittance_from_atlas;      // atlas -> transmittance-map coordinates

// The colour of the light reaching atlas coordinates uvz of tile rect through the transparent
// casters before it: bilinear over the four texels around it, each its transmittance where
// uvz lies beyond its nearest transparent caster and white where it does not (that caster's
// own surface, a surface in front of it).
vec3 shadow_transmittance(vec3 uvz, vec4 rect) {
    vec2 size = vec2(textureSize(u_shadow_transmittance, 0));
    vec2 st = uvz.xy * u_transmittance_from_atlas * size - 0.5;
    ivec2 corner = ivec2(floor(st));
    vec2 f = st - vec2(corner);
    ivec2 low = ivec2(rect.xy * u_transmittance_from_atlas * size + 0.5);
    ivec2 high = ivec2(rect.zw * u_transmittance_from_atlas * size - 0.5);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 texel = clamp(corner + o, low, high);
        float w = mix(1.0 - f.x, f.x, float(o.x)) * mix(1.0 - f.y, f.y, float(o.y));
        bool beyond = uvz.z > texelFetch(u_shadow_transparent_depth, texel, 0).r;
        sum += w * (beyond ? texelFetch(u_shadow_transmittance, texel, 0).rgb : vec3(1.0));
    }
    return sum;
}
#endif

#ifdef OPACITY_SHADOWS
uniform sampler2D u_opacity_first;  // RG32F: light-view depth of the volume's front, - its back
uniform sampler2D u_opacity;        // RGBA16F: optical depth up to each layer's far end
uniform vec4 u_opacity_layers;      // the layers' far ends behind the front, world units
uniform float u_opacity_from_atlas; // atlas -> opacity-map coordinates (their square's scale)
#endif


#ifdef OPACITY_SHADOWS
// The light a surface other than the volume's own keeps at view-space P: the transmittance
// through the whole volume along the tile's light (its last layer, filtered) where P lies
// beyond the volume's back, none of it where P lies a layer's thickness (u_opacity_layers.z:
// the thickest volume's) or more before the back (in front of the volume, or inside it: the
// volume's own surfaces), faded in between. A lit surface of the volume's own lies farther
// than that from the back: its light goes on into the body it covers and out through the
// volume beyond. A surface the volume dips into (a floor under fur) lies within it and takes
// part of the shadow, so where it meets the fur it shows no lit patches stepped at the maps'
// texels. The back is the farthest of the four texels around P's, so a surface inside the
// volume is not taken for one beyond it where the back slopes within a texel.
float opacity_beyond(mat4 to_atlas, vec4 rect, vec4 size, vec3 P) {
    vec4 clip = to_atlas * vec4(P, 1.0);
    vec3 uvz = clip.xyz / clip.w;
    vec2 uv = clamp(uvz.xy, rect.xy, rect.zw) * u_opacity_from_atlas;
    vec2 texels = vec2(textureSize(u_opacity_first, 0));
    ivec2 corner = ivec2(floor(uv * texels - 0.5));
    ivec2 low = ivec2(rect.xy * u_opacity_from_atlas * texels + 0.5);
    ivec2 high = ivec2(rect.zw * u_opacity_from_atlas * texels - 0.5);
    float back = -3.0e38;
    for (int k = 0; k < 4; ++k) {
        ivec2 texel = clamp(corner + ivec2(k & 1, k >> 1), low, high);
        back = max(back, -texelFetch(u_opacity_first, texel, 0).g);
    }
    vec4 b = u_opacity_layers;
    float beyond = clamp((shadow_view_depth(uvz.z, size) - back + b.z) / max(b.z - b.x, 1e-6),
                         0.0, 1.0);
    return mix(1.0, exp(-textureLod(u_opacity, uv, 0.0).w), beyond);
}
#endif

#if defined(OPACITY_RECEIVER) && defined(OPACITY_SHADOWS)

// The front at uv, interpolated bilinearly between the four texels around it that hold one
// (OPACITY_FAR: none of them). Each texel holds the front at its centre: read nearest, the front
// is flat over a texel and steps at its edges, so under a front at a slant to the light the
// depth behind it jumps at every texel's edge, and so does the transmittance there (contour
// bands across the skin of a fur ball, a texel of the maps apart).
float interpolated_front(vec2 uv, vec4 rect) {
    vec2 size = vec2(textureSize(u_opacity_first, 0));
    vec2 st = uv * size - 0.5;
    ivec2 corner = ivec2(floor(st));
    vec2 f = st - vec2(corner);
    ivec2 low = ivec2(rect.xy * u_opacity_from_atlas * size + 0.5);
    ivec2 high = ivec2(rect.zw * u_opacity_from_atlas * size - 0.5);
    float sum = 0.0;
    float weight = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        float front = texelFetch(u_opacity_first, clamp(corner + o, low, high), 0).r;
        float w = mix(1.0 - f.x, f.x, float(o.x)) * mix(1.0 - f.y, f.y, float(o.y));
        if (front < 1.0e37) {
            sum += w * front;
            weight += w;
        }
    }
    return weight > 0.0 ? sum / weight : 3.0e38;
}

// The volume's optical depth in front of view-space P along the tile's light: the layers
// interpolated linearly at P's depth behind the front (0 at the front; the last layer beyond).
float opacity_depth_at(mat4 to_atlas, vec4 rect, vec4 size, vec3 P) {
    vec4 clip = to_atlas * vec4(P, 1.0);
    vec3 uvz = clip.xyz / clip.w;
    vec2 uv = clamp(uvz.xy, rect.xy, rect.zw) * u_opacity_from_atlas;
    float first = interpolated_front(uv, rect);
    if (first > 1.0e37) {  // no volume around (the fronts are grown by a texel)
        if (opacity_seen.x < 0.0) opacity_seen = vec3(0.0);  // the view shows this light's
        return 0.0;
    }
    float behind = shadow_view_depth(uvz.z, size) - first;
    vec4 layers = textureLod(u_opacity, uv, 0.0);
    if (opacity_seen.x < 0.0) opacity_seen = 1.0 - exp(-layers.xyw);
    vec4 b = u_opacity_layers;
    // piecewise linear through (0, 0), (b.x, layers.x) .. (b.w, layers.w)
    float t0 = clamp(behind / b.x, 0.0, 1.0);
    float t1 = clamp((behind - b.x) / (b.y - b.x), 0.0, 1.0);
    float t2 = clamp((behind - b.y) / (b.z - b.y), 0.0, 1.0);
    float t3 = clamp((behind - b.z) / (b.w - b.z), 0.0, 1.0);
    return layers.x * t0 + (layers.y - layers.x) * t1 + (layers.z - layers.y) * t2
         + (layers.w - layers.z) * t3;
}

float opacity_transmittance(mat4 to_atlas, vec4 rect, vec4 size, vec3 P) {
    return exp(-opacity_depth_at(to_atlas, rect, size, P));
}
#endif

float shadow_compare(vec3 uvz, vec4 rect) {
    // kept half a texel inside the tile: bilinear comparison never reads a neighbour's texels;
    // level 0 given (the atlas has no mipmaps): no derivatives to find a level from
    vec2 margin = vec2(0.5 * u_shadow_atlas_texel);
    return textureLod(u_shadow_atlas, vec3(clamp(uvz.xy, rect.xy + margin, rect.zw - margin),
                                           uvz.z), 0.0);
}

#if defined(SHADOW_PCSS) || defined(SURFACE_TRANSMISSION)
uniform sampler2D u_shadow_depths;  // the atlas's depths, read without comparison
#endif

#ifdef SHADOW_PCSS
const float PCSS_MAX_REACH = 0.25;  // of a tile: the widest search and filter
const int PCSS_SEARCH_TAPS = 16;
const int PCSS_FILTER_TAPS = 24;

// The disk of the soft filter (SHADOW_POISSON, 16 taps) and its mirror turned a little, for
// 32 taps, rotated by the pixel's angle
vec2 pcss_tap(int k, mat2 turn) {
    vec2 tap = SHADOW_POISSON[k & 15];
    if (k >= 16) tap = vec2(-tap.y, tap.x) * 0.7;
    return turn * tap;
}

mat2 pcss_turn() {
    float noise = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
    float angle = 6.28318530718 * noise;
    return mat2(cos(angle), sin(angle), -sin(angle), cos(angle));
}

// The lit fraction at uvz (a perspective tile: rect, size as shadow_tile reads them) of a light
// of emitter radius r (world units); slope: the receiver's plane's depth per atlas unit, so a
// tap far from the centre compares the plane's own depth there, not the centre's (a wide
// filter on a plane at a slant to the light would shadow the plane by itself)
float shadow_pcss(vec3 uvz, vec4 rect, vec4 size, float r, vec2 slope) {
    float tile = rect.z - rect.x;  // atlas units across the tile
    float tan_half = 0.5 * size.x * tile / u_shadow_atlas_texel;
    float receiver = shadow_view_depth(uvz.z, size);
    float to_atlas = r * tile / (2.0 * tan_half);  // per unit of inverse depth
    float search = min(to_atlas * (1.0 / size.z - 1.0 / receiver), PCSS_MAX_REACH * tile);
    mat2 turn = pcss_turn();
    // a texel's value is the depth at its centre: the plane's own texels may lie up to a texel's
    // slope nearer than the plane at the tap
    float slack = length(slope) * 1.5 * u_shadow_atlas_texel;
    float blockers = 0.0;
    float found = 0.0;
    // taps past the tile's edge see another face's part of the scene: left out, not clamped
    vec2 low = rect.xy + vec2(0.5 * u_shadow_atlas_texel);
    vec2 high = rect.zw - vec2(0.5 * u_shadow_atlas_texel);
    for (int k = 0; k < PCSS_SEARCH_TAPS; ++k) {
        vec2 offset = pcss_tap(k, turn) * search;
        vec2 uv = uvz.xy + offset;
        if (any(lessThan(uv, low)) || any(greaterThan(uv, high))) continue;
        float depth = textureLod(u_shadow_depths, uv, 0.0).r;
        // nearer than the receiver's plane there, and than the receiver (the plane carried
        // far past the point may pass behind the far plane, where the map holds nothing)
        if (depth < min(uvz.z + dot(slope, offset) - slack, uvz.z)) {
            blockers += shadow_view_depth(depth, size);
            found += 1.0;
        }
    }
    if (found == 0.0) return 1.0;
    float blocker = blockers / found;
    float width = clamp(to_atlas * (1.0 / blocker - 1.0 / receiver), u_shadow_atlas_texel,
                        PCSS_MAX_REACH * tile);
    float lit = 0.0;
    float taps = 0.0;
    for (int k = 0; k < PCSS_FILTER_TAPS; ++k) {
        vec2 offset = pcss_tap(k, turn) * width;
        vec2 uv = uvz.xy + offset;
        if (any(lessThan(uv, low)) || any(greaterThan(uv, high))) continue;
        lit += shadow_compare(vec3(uvz.xy + offset,
                                   min(uvz.z + dot(slope, offset) - slack, 1.0)), rect);
        taps += 1.0;
    }
    return taps > 0.0 ? lit / taps : 1.0;
}

// The depth slope of the plane through view-space Q of normal N, per atlas unit
vec2 pcss_slope(mat4 to_atlas, vec3 Q, vec3 N, float step) {
    vec3 T1 = normalize(cross(N, abs(N.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 T2 = cross(N, T1);
    vec4 a = to_atlas * vec4(Q, 1.0), b = to_atlas * vec4(Q + T1 * step, 1.0),
         c = to_atlas * vec4(Q + T2 * step, 1.0);
    vec3 A = a.xyz / a.w, B = b.xyz / b.w, C = c.xyz / c.w;
    mat2 across = mat2(B.xy - A.xy, C.xy - A.xy);  // columns: each step's atlas offset
    float det = determinant(across);
    if (abs(det) < 1e-12) return vec2(0.0);
    // the gradient g with dot(g, offset) = the depth change of each step
    return inverse(transpose(across)) * vec2(B.z - A.z, C.z - A.z);
}
#endif

// The lit fraction of a point at atlas coordinates uvz in tile rect: one loop whichever the
// filter, so a light pays for its own filter's taps only (where a shader runs as masked SIMD
// lanes, as on llvmpipe, the two branches of an `if` both run).
// - pcf: a 3x3 grid of bilinear comparisons a texel apart weighs the 4x4 texels around uvz by
//   (1 - f, 1, 1, f) along each axis (f the fraction of uvz between texel centres). Two bilinear
//   comparisons per axis give the same weights: one over the first two texels, placed
//   1 / (2 - f) of a texel past the first, of weight 2 - f; one over the last two, f / (1 + f)
//   past the third, of weight 1 + f. So 2x2 lookups, not 9 (the optimised PCF of shadow
//   mapping practice; the filter is unchanged).
// - soft: SHADOW_POISSON, header.w texels wide.
float shadow_filter(vec3 uvz, vec4 rect, vec4 header) {
    bool soft = header.z > 0.5;
    int taps = soft ? 16 : 4;
    float scale = header.w * u_shadow_atlas_texel;
    vec2 st = uvz.xy / u_shadow_atlas_texel - 0.5;  // texel-centre coordinates
    vec2 first = floor(st);
    vec2 f = st - first;
    vec2 w_low = 2.0 - f, w_high = 1.0 + f;
    vec2 uv_low = (first - 0.5 + 1.0 / w_low) * u_shadow_atlas_texel;
    vec2 uv_high = (first + 1.5 + f / w_high) * u_shadow_atlas_texel;
    float lit = 0.0;
    int k = 0;
    do {
        vec2 high = vec2(float(k & 1), float(k >> 1));
        vec2 uv = soft ? uvz.xy + SHADOW_POISSON[k] * scale : mix(uv_low, uv_high, high);
        vec2 w = mix(w_low, w_high, high);
        float weight = soft ? 1.0 / 16.0 : w.x * w.y / 9.0;
        lit += weight * shadow_compare(vec3(uv, uvz.z), rect);
    } while (++k < taps);
    return lit;
}

// The tile's filter at uvz: shadow_filter's, or PCSS's where the light asks for it (its emitter
// radius in biases.w; Q the biased point and N its normal, for the receiver's plane)
float shadow_lookup(vec3 uvz, vec4 rect, vec4 header, vec4 size, vec4 biases, mat4 to_atlas,
                    vec3 Q, vec3 N, float texel) {
#ifdef SHADOW_PCSS
    if (header.z > 1.5)
        return shadow_pcss(uvz, rect, size, biases.w, pcss_slope(to_atlas, Q, N, 8.0 * texel));
#endif
    return shadow_filter(uvz, rect, header);
}

// The lit fraction of a tile's depth maps as a colour: times the transmittance of the
// transparent casters before the point where the scene has them.
vec3 shadow_tint(float lit, vec3 uvz, vec4 rect) {
#ifdef SHADOW_TRANSMITTANCE
    return lit * shadow_transmittance(uvz, rect);
#else
    return vec3(lit);
#endif
}

// One tile's lit fraction at view-space P (normal N, unit L toward the light, distance to it),
// per channel.
vec3 shadow_tile(int row, int tile, vec4 header, vec4 biases, vec3 P, vec3 N, vec3 L,
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
    if (uvz.z >= 1.0) return vec3(1.0);  // beyond the map's far plane
#if defined(OPACITY_RECEIVER) && defined(OPACITY_SHADOWS)
    float transmittance = opacity_transmittance(to_atlas, rect, size, P);
    opacity_last = transmittance;
    float lit = shadow_lookup(uvz, rect, header, size, biases, to_atlas, Q, N, texel);
    if (opacity_as_light_pass) return shadow_tint(lit * opacity_beyond(to_atlas, rect, size, P),
                                                  uvz, rect);
    return shadow_tint(lit * (opacity_split ? 1.0 : transmittance), uvz, rect);
#elif defined(OPACITY_SHADOWS)
    return shadow_tint(shadow_lookup(uvz, rect, header, size, biases, to_atlas, Q, N, texel) *
                       opacity_beyond(to_atlas, rect, size, P), uvz, rect);
#else
    return shadow_tint(shadow_lookup(uvz, rect, header, size, biases, to_atlas, Q, N, texel),
                       uvz, rect);
#endif
}

// The fraction of a light reaching view-space P on a surface of normal N (1: lit, 0: shadow),
// per channel, L unit toward the light: one function per projection (deferred.names.ShadowProjection), which
// a light type's GLSL calls for its own, so no light runs another projection's code.
vec3 light_shadow_cascades(LightRecord light, vec3 P, vec3 N, vec3 L) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return vec3(SHADOW_UNSHADOWED);
    int row = slot - 1;
    vec4 header = shadow_texel(row, 0);
    vec4 biases = shadow_texel(row, 1);
    vec4 splits = shadow_texel(row, 2);
    int count = int(header.y + 0.5);
    float depth = -P.z;
    if (depth > splits[count - 1]) return vec3(SHADOW_UNSHADOWED);  // beyond the shadow distance
    // the first cascade whose far depth lies beyond P (a cheap loop, then one lookup)
    int i = 0;
    float near = 0.0;
    for (int k = 0; k < 3; ++k) {
        if (k + 1 < count && depth > splits[k]) {
            i = k + 1;
            near = splits[k];
        }
    }
    float far = splits[i];
    vec3 lit = shadow_tile(row, i, header, biases, P, N, L, 1.0);
    // blended into the next over the last CASCADE_BLEND of its depth range: no seam
    float band = biases.z * (far - near);
    float t = i + 1 < count ? smoothstep(far - band, far, depth) : 0.0;
    if (t > 0.0) lit = mix(lit, shadow_tile(row, i + 1, header, biases, P, N, L, 1.0), t);
    return lit;
}

vec3 light_shadow_perspective(LightRecord light, vec3 P, vec3 N, vec3 L) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return vec3(SHADOW_UNSHADOWED);
    int row = slot - 1;
    return shadow_tile(row, 0, shadow_texel(row, 0), shadow_texel(row, 1), P, N, L,
                       length(P - light.position.xyz));
}

vec3 light_shadow_cube(LightRecord light, vec3 P, vec3 N, vec3 L) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return vec3(SHADOW_UNSHADOWED);
    int row = slot - 1;
    // the face of the direction's major axis in world space (+X, -X, +Y, -Y, +Z, -Z)
    vec3 d = u_shadow_world_from_view * (P - light.position.xyz);
    vec3 a = abs(d);
    int face = a.x >= a.y && a.x >= a.z ? (d.x >= 0.0 ? 0 : 1)
             : a.y >= a.z ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
    return shadow_tile(row, face, shadow_texel(row, 0), shadow_texel(row, 1), P, N, L,
                       length(d));
}
#ifdef SURFACE_TRANSMISSION
// The distance the light travels inside a surface to reach view-space P (normal N): P's depth
// from the light less the depth of the first surface the map saw along the same ray (Jimenez et
// al. 2010), P moved a little inside first, so a point at an edge the light grazes reads its own
// body's front, not its own depth. Along the ray for a perspective tile (its depth is along the
// tile's axis). 1e30 where P lies outside the tile: no light through.
float shadow_tile_thickness(int row, int tile, vec3 P, vec3 N, float distance) {
    int base = 4 + 6 * tile;
    mat4 to_atlas = mat4(shadow_texel(row, base), shadow_texel(row, base + 1),
                         shadow_texel(row, base + 2), shadow_texel(row, base + 3));
    vec4 rect = shadow_texel(row, base + 4);
    vec4 size = shadow_texel(row, base + 5);
    float texel = size.x * (size.y > 0.5 ? distance : 1.0);
    vec4 clip = to_atlas * vec4(P - N * (2.0 * texel), 1.0);
    vec3 uvz = clip.xyz / clip.w;
    if (any(lessThan(uvz.xy, rect.xy)) || any(greaterThan(uvz.xy, rect.zw)) || uvz.z >= 1.0)
        return 1e30;
    float receiver = shadow_view_depth(uvz.z, size);
    float first = shadow_view_depth(textureLod(u_shadow_depths, uvz.xy, 0.0).r, size);
    float along = size.y > 0.5 ? distance / max(receiver, 1e-6) : 1.0;
    return max(receiver - first, 0.0) * along;
}

float light_thickness_cascades(LightRecord light, vec3 P, vec3 N) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return 1e30;
    int row = slot - 1;
    vec4 splits = shadow_texel(row, 2);
    int count = int(shadow_texel(row, 0).y + 0.5);
    float depth = -P.z;
    if (depth > splits[count - 1]) return 1e30;
    int i = 0;
    for (int k = 0; k < 3; ++k)
        if (k + 1 < count && depth > splits[k]) i = k + 1;
    return shadow_tile_thickness(row, i, P, N, 1.0);
}

float light_thickness_perspective(LightRecord light, vec3 P, vec3 N) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return 1e30;
    return shadow_tile_thickness(slot - 1, 0, P, N, length(P - light.position.xyz));
}

float light_thickness_cube(LightRecord light, vec3 P, vec3 N) {
    int slot = int(light.extra.w + 0.5);
    if (slot <= 0) return 1e30;
    vec3 d = u_shadow_world_from_view * (P - light.position.xyz);
    vec3 a = abs(d);
    int face = a.x >= a.y && a.x >= a.z ? (d.x >= 0.0 ? 0 : 1)
             : a.y >= a.z ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
    return shadow_tile_thickness(slot - 1, face, P, N, length(d));
}
#endif
#else
vec3 light_shadow_cascades(LightRecord light, vec3 P, vec3 N, vec3 L) {
    return vec3(SHADOW_UNSHADOWED);
}

vec3 light_shadow_perspective(LightRecord light, vec3 P, vec3 N, vec3 L) {
    return vec3(SHADOW_UNSHADOWED);
}

vec3 light_shadow_cube(LightRecord light, vec3 P, vec3 N, vec3 L) {
    return vec3(SHADOW_UNSHADOWED);
}
#ifdef SURFACE_TRANSMISSION
float light_thickness_cascades(LightRecord light, vec3 P, vec3 N) { return 1e30; }
float light_thickness_perspective(LightRecord light, vec3 P, vec3 N) { return 1e30; }
float light_thickness_cube(LightRecord light, vec3 P, vec3 N) { return 1e30; }
#endif
#endif
