// The fur's light per pixel (materials/techniques/fur_light.py): the irradiance of the fur at
// this pixel, else of the first neighbour holding it (the order of base_irradiance's search),
// and the linear depth of the pixel it came from: > 0 this pixel's, < 0 a neighbour's, 0 none.
// The search reads only surface ids, and the light and depth of the one pixel it chose: a CPU
// rasteriser runs every branch, so reading them in the search would read them nine times.
#include "techniques/accumulated_light.glsl"

out vec4 out_light;

bool holds_surface(ivec2 pixel) {
    return inside(pixel)
        && same_surface(texelFetch(u_normal_exponent_id, pixel, 0).w, u_surface_id);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    ivec2 neighbour = pixel;
    bool found = false;
    for (int k = 7; k >= 0; --k) {  // backwards: the first in AROUND's order is kept
        ivec2 q = pixel + AROUND[k];
        if (holds_surface(q)) {
            neighbour = q;
            found = true;
        }
    }
    bool own = holds_surface(pixel);
    ivec2 chosen = own ? pixel : neighbour;
    float depth = texelFetch(u_linear_depth, chosen, 0).r;
    out_light = own || found ? vec4(irradiance_at(chosen), own ? depth : -depth) : vec4(0.0);
}
