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
