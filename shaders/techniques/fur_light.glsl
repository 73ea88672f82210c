// A fur layer fragment's light from the fur_light target (materials/techniques/fur_light.py):
// one texel instead of base_irradiance's search, the same answer where the pixel under the
// base point, or the first neighbour holding the fur, lies within `tolerance` of the expected
// depth. Include techniques/accumulated_light.glsl first (pixel_of, inside).
uniform sampler2D u_fur_light;  // the material's fur_light target (fur_light.py)

// The base sample: the fur's light at `pixel` (or its first neighbour holding the fur), if that
// sample's depth is within `tolerance` of `expected_depth`.
bool fur_light_at(ivec2 pixel, float expected_depth, float tolerance, out vec3 irradiance) {
    vec4 s = inside(pixel) ? texelFetch(u_fur_light, pixel, 0) : vec4(0.0);
    irradiance = s.rgb;
    return s.a != 0.0 && abs(abs(s.a) - expected_depth) <= tolerance;
}

// The fragment's own pixel, if it holds the fur (the last resort of a hidden base).
bool own_fur_light(out vec3 irradiance) {
    vec4 s = texelFetch(u_fur_light, ivec2(gl_FragCoord.xy), 0);
    irradiance = s.rgb;
    return s.a > 0.0;
}
