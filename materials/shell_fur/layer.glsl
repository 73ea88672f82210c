// A fragment of a shell_fur layer: where its colour and strands come from after clumping
// (Algorithm 2), and the screen gradients of both lookups (within a clump they change 1 + gain
// times as fast as the undisplaced coordinates: the displacement's own jumps at clump rims must
// not choose the mip level). With FUR_UV_MAPPING the strands are looked up over the UVs, as
// the paper does (uv_geo += d); otherwise triplanar in the fur volume's world-scaled object
// space, the UV displacement carried there through d(position)/d(uv). Call in uniform control
// flow: it takes screen derivatives.
#include "materials/shell_fur/clump.glsl"

struct FurLayer {
    vec2 color_uv;      // colour texture coordinate
    vec2 color_dx;      // its screen gradients
    vec2 color_dy;
    vec3 fur_position;  // fur volume position (world units, object axes)
    vec3 fur_dx;        // its screen gradients
    vec3 fur_dy;
    bool kept;          // false: Algorithm 2 ignores the fragment
};

FurLayer fur_layer(vec2 uv, vec3 fur_position, float h, bool skin) {
    vec2 dudx = dFdx(uv);
    vec2 dudy = dFdy(uv);
#ifdef FUR_UV_MAPPING
    vec3 dpdx = vec3(0.0), dpdy = vec3(0.0), dpdu = vec3(0.0), dpdv = vec3(0.0);
#else
    // d(fur position) / d(uv) from screen derivatives: both are affine over a triangle. Where
    // the UVs do not span the screen footprint (a fin, extruded along constant UVs) there is
    // none, and clumps do not move the fur.
    vec3 dpdx = dFdx(fur_position);
    vec3 dpdy = dFdy(fur_position);
    float det = dudx.x * dudy.y - dudy.x * dudx.y;
    bool spans = abs(det) > 1e-4 * length(dudx) * length(dudy);
    vec3 dpdu = spans ? (dpdx * dudy.y - dpdy * dudx.y) / det : vec3(0.0);
    vec3 dpdv = spans ? (dpdy * dudx.x - dpdx * dudy.x) / det : vec3(0.0);
#endif
    vec2 d = vec2(0.0);
    float gain = 0.0;
    bool kept = skin || clump_fur(uv, h, d, gain);  // the skin under the fur does not clump
    float rate = 1.0 + gain;
    FurLayer layer;
    layer.color_uv = uv + d;
    layer.color_dx = rate * dudx;
    layer.color_dy = rate * dudy;
    layer.fur_position = fur_position + dpdu * d.x + dpdv * d.y;
    layer.fur_dx = rate * dpdx;
    layer.fur_dy = rate * dpdy;
    layer.kept = kept;
    return layer;
}
