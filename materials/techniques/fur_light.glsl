// A fur layer fragment's light from a fur_light gather (materials/techniques/fur_light.py): two
// texels instead of base_irradiance's search. Include materials/techniques/accumulated_light.glsl first
// (pixel_of, inside).
uniform sampler2D u_fur_light;         // irradiance; 1 this pixel's, -1 a neighbour's, 0 none
uniform sampler2D u_fur_light_depths;  // least and greatest depth of the fur over 3x3 pixels

// The base sample: the fur's light at `pixel` (or its first neighbour holding the fur), if the
// fur there spans `expected_depth` within `tolerance`.
// A base pixel one off the screen reads the pixel inside: the search found its light among its
// neighbours there.
bool fur_light_at(ivec2 pixel, float expected_depth, float tolerance, out vec3 irradiance) {
    ivec2 clamped = clamp(pixel, ivec2(0), ivec2(u_resolution) - 1);
    bool near = all(lessThanEqual(abs(pixel - clamped), ivec2(1)));
    vec4 s = near ? texelFetch(u_fur_light, clamped, 0) : vec4(0.0);
    vec2 depths = near ? texelFetch(u_fur_light_depths, clamped, 0).rg : vec2(0.0);
    irradiance = s.rgb;
    return s.a != 0.0 && expected_depth >= depths.x - tolerance
        && expected_depth <= depths.y + tolerance;
}

// The fragment's own pixel, if it holds the fur (the last resort of a hidden base).
bool own_fur_light(out vec3 irradiance) {
    vec4 s = texelFetch(u_fur_light, ivec2(gl_FragCoord.xy), 0);
    irradiance = s.rgb;
    return s.a > 0.0;
}
