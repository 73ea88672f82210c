// Hatching from a tonal art map (Costigan 2.4.3, 4.3.8; Praun et al. 2001; Lake et al. 2000).
// The TAM is one single-channel texture (materials/techniques/hatching.py, tam_texture): its
// `tones` images of ink (0 paper, 1 full ink; tone 0 the lightest) side by side in square
// cells, each padded by `gutter` texels of its own wrapped pixels at level 0 (gutter >> m at
// level m), with the TAM's own mip levels. A cell's tile is sampled through its gutter, so
// hardware filtering tiles seamlessly at every level without GL_REPEAT.
//
// A lit tone in [0, 1] (1: lit, paper; 0: the darkest tone) picks the two nearest TAM tones,
// mixed linearly: the thesis' per-pixel successor (4.3.8) of Praun's 6-way blend. With s =
// (1 - tone) * tones, s = 0 is paper and s = k the k-th tone (index k - 1).

// Ink of tone `index` at texture coordinates `uv` (tiling), with uv's screen derivatives.
float hatching_tone_ink(sampler2D tam, int tones, int gutter, int index, vec2 uv,
                        vec2 duv_dx, vec2 duv_dy) {
    vec2 atlas = vec2(textureSize(tam, 0));
    float cell = atlas.y;
    float tile = cell - 2.0 * float(gutter);
    vec2 texel = fract(uv) * tile + float(gutter);
    texel.x += float(index) * cell;
    vec2 scale = tile / atlas;  // uv to atlas coordinates, for the derivatives
    return textureGrad(tam, texel / atlas, duv_dx * scale, duv_dy * scale).r;
}

// The blend of the two tones nearest `tone`, with explicit derivatives (the level of detail).
float hatching_ink_grad(sampler2D tam, int tones, int gutter, float tone, vec2 uv,
                        vec2 duv_dx, vec2 duv_dy) {
    float s = clamp(1.0 - tone, 0.0, 1.0) * float(tones);
    float darker = min(floor(s), float(tones - 1));
    int index = int(darker);
    float dark = hatching_tone_ink(tam, tones, gutter, index, uv, duv_dx, duv_dy);
    float light = index > 0
        ? hatching_tone_ink(tam, tones, gutter, index - 1, uv, duv_dx, duv_dy) : 0.0;
    return mix(light, dark, s - darker);
}

// Surface hatching (Praun et al., Fig. 4.20b): the TAM as the surface's texture at `uv`; its
// mip levels keep strokes at their width in pixels as the surface recedes. Fragment shaders
// only (screen derivatives); call it in uniform control flow.
float hatching_ink(sampler2D tam, int tones, int gutter, float tone, vec2 uv) {
    return hatching_ink_grad(tam, tones, gutter, tone, uv, dFdx(uv), dFdy(uv));
}

// Screen-space hatching (Lake et al., Fig. 4.20a): the TAM laid over the screen from pixel
// `frag_coord` (gl_FragCoord.xy), one TAM texel to `scale` pixels; the strokes stay where they
// are on the screen as the object moves. A scale under 1 reads the coarser levels.
float hatching_screen_ink(sampler2D tam, int tones, int gutter, float tone, vec2 frag_coord,
                          float scale) {
    float tile = float(textureSize(tam, 0).y - 2 * gutter) * scale;
    float step_uv = 1.0 / tile;
    return hatching_ink_grad(tam, tones, gutter, tone, frag_coord * step_uv,
                             vec2(step_uv, 0.0), vec2(0.0, step_uv));
}

// Pen hatching (Costigan 4.3.8 at a stroke width in pixels): the tones' blend read from ONE
// level, the nearest to one texel a pixel across the pixel's footprint's shorter axis (up to
// PEN_TAPS samples along its longer one: anisotropic filtering), so a stroke is about the map's
// stroke width in pixels at any distance and slant (the TAM's levels draw their strokes
// equally wide in texels; trilinear
// filtering between two levels that hold different strokes would leave half-inked ghosts of
// the strokes one of them drops), then made crisp: the ink thresholded at half a stroke's, over
// about one pixel (fwidth), so a magnified stroke keeps a pen's edge instead of a smear. Past
// the coarsest level (a stroke would be under a pixel: moire), or where the footprint is more
// slanted than the taps resolve, the strokes fade into their tone's mean ink (u_tam_mean, a
// value a tone), flat, as the map averaged.
// `mips` the TAM's levels; `duv_dx`, `duv_dy` the uv's screen derivatives. Fragment shaders
// only (fwidth); call it in uniform control flow.
uniform float u_tam_mean[64];  // each tone's mean ink at the coarsest level
const int PEN_TAPS = 4;

float hatching_tone_ink_at(sampler2D tam, int gutter, int index, vec2 uv, float level) {
    vec2 atlas = vec2(textureSize(tam, 0));
    float cell = atlas.y;
    float tile = cell - 2.0 * float(gutter);
    vec2 texel = fract(uv) * tile + float(gutter);
    texel.x += float(index) * cell;
    return textureLod(tam, texel / atlas, level).r;
}

float hatching_pen_ink(sampler2D tam, int tones, int gutter, int mips, float tone, vec2 uv,
                       vec2 duv_dx, vec2 duv_dy) {
    float tile = float(textureSize(tam, 0).y - 2 * gutter);
    // the pixel's footprint in level-0 texels: its longer axis is read in up to PEN_TAPS
    // samples along it (anisotropic filtering), so the level follows the shorter axis (strokes
    // stay their width across however the surface is foreshortened along them)
    vec2 x = duv_dx * tile;
    vec2 y = duv_dy * tile;
    bool x_major = dot(x, x) >= dot(y, y);
    vec2 major_uv = x_major ? duv_dx : duv_dy;
    float major = max(length(x_major ? x : y), 1e-6);
    float minor = max(length(x_major ? y : x), 1e-6);
    int taps = int(clamp(ceil(major / minor), 1.0, float(PEN_TAPS)));
    float lod = log2(major / float(taps));
    float level = clamp(floor(lod + 0.5), 0.0, float(mips - 1));
    float s = clamp(1.0 - tone, 0.0, 1.0) * float(tones);
    float darker = min(floor(s), float(tones - 1));
    int index = int(darker);
    float weight = s - darker;
    float ink = 0.0;
    for (int k = 0; k < PEN_TAPS; ++k) {
        if (k >= taps) break;
        vec2 at = uv + major_uv * ((float(k) + 0.5) / float(taps) - 0.5);
        float dark = hatching_tone_ink_at(tam, gutter, index, at, level);
        float light = index > 0 ? hatching_tone_ink_at(tam, gutter, index - 1, at, level) : 0.0;
        ink += mix(light, dark, weight);
    }
    ink /= float(taps);
    float edge = 0.5 * fwidth(ink) + 1e-3;
    float crisp = smoothstep(0.5 - edge, 0.5 + edge, ink);
    float mean = mix(index > 0 ? u_tam_mean[index - 1] : 0.0, u_tam_mean[index], weight);
    // finer than the coarsest level, or slanted more than the taps resolve: flat
    float too_fine = clamp(max(lod - float(mips - 1) - 0.5,
                               log2(major / (minor * float(PEN_TAPS)))), 0.0, 1.0);
    return mix(crisp, mean, too_fine);
}
