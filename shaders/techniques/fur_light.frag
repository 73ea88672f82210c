// The fur's light per pixel (materials/techniques/fur_light.py): the irradiance of the fur at
// this pixel, else of the first neighbour holding it (the order of base_irradiance's search),
// and the linear depth of the pixel it came from: > 0 this pixel's, < 0 a neighbour's, 0 none.
#include "techniques/accumulated_light.glsl"

out vec4 out_light;

bool holds_surface(ivec2 pixel) {
#ifdef FUR_STIPPLE
    if (stipple_sample(pixel)) return false;
#endif
    return inside(pixel)
        && same_surface(texelFetch(u_normal_exponent_id, pixel, 0).w, u_surface_id);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    out_light = vec4(0.0);
    if (holds_surface(pixel)) {
        out_light = vec4(irradiance_at(pixel), texelFetch(u_linear_depth, pixel, 0).r);
        return;
    }
    for (int k = 0; k < 8; ++k) {
        ivec2 q = pixel + AROUND[k];
        if (holds_surface(q)) {
            out_light = vec4(irradiance_at(q), -texelFetch(u_linear_depth, q, 0).r);
            return;
        }
    }
}
