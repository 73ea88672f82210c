// The viewer's viewport: one image, or two side by side at a split, or their difference.
// The images are the renderers' 8-bit sRGB finals (or a buffer view's display image), bottom
// row first as GL keeps them. Where the viewport is their size each pixel is fetched
// unfiltered, so the window shows exactly the pixels `deferred render` writes; reduced frames
// (while the camera moves) are filtered up. A program per view (MODE: 0 single, 1 split,
// 2 difference) and per EXACT (the viewport is the images' size): llvmpipe runs every branch
// of a shader, so a branch on a uniform costs what both sides cost.
#version 330
#ifndef MODE
#define MODE 0
#endif
uniform sampler2D u_left;        // the image (single), the left side (split), A (difference)
uniform sampler2D u_right;       // the right side (split), B (difference)
uniform float u_split;           // split position, 0..1 of the viewport's width
uniform float u_gain;            // difference: |A - B| times this
uniform vec2 u_origin;           // the viewport's lower left corner in window pixels
uniform float u_width;           // the viewport's width in window pixels
in vec2 v_uv;
out vec4 out_color;

vec4 sample_image(sampler2D image) {
#ifdef EXACT
    ivec2 size = textureSize(image, 0);
    ivec2 texel = clamp(ivec2(gl_FragCoord.xy - u_origin), ivec2(0), size - 1);
    return texelFetch(image, texel, 0);
#else
    return texture(image, v_uv);
#endif
}

void main() {
    vec4 left = sample_image(u_left);
#if MODE == 0
    out_color = vec4(left.rgb, 1.0);
#else
    vec4 right = sample_image(u_right);
#if MODE == 2
    out_color = vec4(min(abs(left.rgb - right.rgb) * u_gain, vec3(1.0)), 1.0);
#else
    float column = gl_FragCoord.x - u_origin.x;
    float split = floor(u_split * u_width);
    if (column >= split && column < split + 1.0) {
        out_color = vec4(0.9, 0.9, 0.9, 1.0);  // the divider
        return;
    }
    out_color = vec4((column < split ? left : right).rgb, 1.0);
#endif
#endif
}
