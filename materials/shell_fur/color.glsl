// The fur's colour (Silva et al. section 4, Fig. 3): the colour texture (an image, or a generated
// pattern) over the mesh's UVs, tinted. Without FUR_COLOR_MAP (neither) the fur is the tint: a
// CPU rasteriser runs every lookup, a white texture's too.
uniform sampler2D u_color_map;  // linear RGB (an sRGB image is decoded on load)
uniform vec3 u_color;           // tint
uniform float u_color_scale;    // repeats of the texture across the UV square

vec3 fur_color(vec2 uv) {
#ifdef FUR_COLOR_MAP
    return u_color * texture(u_color_map, uv * u_color_scale).rgb;
#else
    return u_color;
#endif
}

// With explicit screen gradients of uv (clumped coordinates, layer.glsl).
vec3 fur_color_grad(vec2 uv, vec2 dx, vec2 dy) {
#ifdef FUR_COLOR_MAP
    return u_color * textureGrad(u_color_map, uv * u_color_scale, dx * u_color_scale,
                                 dy * u_color_scale).rgb;
#else
    return u_color;
#endif
}
