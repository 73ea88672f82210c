// The viewer's viewport: one image, or two side by side at a split, or their difference.
// The images are the renderers' 8-bit sRGB finals (or a buffer view's display image), bottom
// row first as GL keeps them. Where the viewport is their size each pixel is fetched
// unfiltered, so the window shows exactly the pixels `deferred render` writes; reduced frames
// (while the camera moves) are filtered up.
#version 330
uniform sampler2D u_left;        // the image (single), the left side (split), A (difference)
uniform sampler2D u_right;       // the right side (split), B (difference)
uniform int u_mode;              // 0 single, 1 split, 2 difference
uniform float u_split;           // split position, 0..1 of the viewport's width
uniform float u_gain;            // difference: |A - B| times this
uniform bool u_exact;            // the viewport is the images' size: fetch, do not filter
uniform vec2 u_origin;           // the viewport's lower left corner in window pixels
uniform float u_width;           // the viewport's width in window pixels
in vec2 v_uv;
out vec4 out_color;

vec4 sample_image(sampler2D image) {
    if (u_exact) {
        ivec2 size = textureSize(image, 0);
        ivec2 texel = clamp(ivec2(gl_FragCoord.xy - u_origin), ivec2(0), size - 1);
        return texelFetch(image, texel, 0);
    }
    return texture(image, v_uv);
}

void main() {
    vec4 left = sample_image(u_left);
    if (u_mode == 0) {
        out_color = vec4(left.rgb, 1.0);
        return;
    }
    vec4 right = sample_image(u_right);
    if (u_mode == 2) {
        out_color = vec4(min(abs(left.rgb - right.rgb) * u_gain, vec3(1.0)), 1.0);
        return;
    }
    float column = gl_FragCoord.x - u_origin.x;
    float split = floor(u_split * u_width);
    if (column >= split && column < split + 1.0) {
        out_color = vec4(0.9, 0.9, 0.9, 1.0);  // the divider
        return;
    }
    out_color = vec4((column < split ? left : right).rgb, 1.0);
}
