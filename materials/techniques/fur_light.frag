// The fur's light per pixel (materials/techniques/fur_light.py): the irradiance of the fur at
// this pixel, else of the first neighbour holding it (the order of base_irradiance's search),
// with where it came from (1 this pixel, -1 a neighbour, 0 none); and the least and greatest
// linear depth of the fur over the 3x3 pixels. The search reads only ids and depths, and the
// light of the one pixel it chose: a CPU rasteriser runs every branch, so reading the light in
// the search would read it nine times.
#include "materials/techniques/accumulated_light.glsl"

layout(location = 0) out vec4 out_light;
layout(location = 1) out vec2 out_depths;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    ivec2 neighbour = pixel;
    bool found = false;
    vec2 depths = vec2(3.0e38, 0.0);
    for (int k = 7; k >= 0; --k) {  // backwards: the first in AROUND's order is kept
        ivec2 q = pixel + AROUND[k];
        if (inside(q) && holds_surface(q)) {
            float depth = texelFetch(u_linear_depth, q, 0).r;
            depths = vec2(min(depths.x, depth), max(depths.y, depth));
            neighbour = q;
            found = true;
        }
    }
    bool own = holds_surface(pixel);  // a fragment's own pixel is on the screen
    if (own) {
        float depth = texelFetch(u_linear_depth, pixel, 0).r;
        depths = vec2(min(depths.x, depth), max(depths.y, depth));
    }
    ivec2 chosen = own ? pixel : neighbour;
    out_light = own || found ? vec4(irradiance_at(chosen), own ? 1.0 : -1.0) : vec4(0.0);
    out_depths = own || found ? depths : vec2(0.0);
}
