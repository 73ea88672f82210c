// A fragment of a shell_fur layer: where its colour and strands come from after clumping
// (Algorithm 2), with the clump displacement taken from the mesh's UVs to the fur volume's
// world-scaled object space (the shared technique looks strands up triplanar there). Call in
// uniform control flow: it takes screen derivatives, and so do the lookups after it.
#include "materials/shell_fur/clump.glsl"

struct FurLayer {
    vec2 color_uv;      // colour texture coordinate
    vec3 fur_position;  // fur volume position (world units, object axes)
    bool kept;          // false: Algorithm 2 ignores the fragment
};

FurLayer fur_layer(vec2 uv, vec3 fur_position, float h, bool skin) {
    // d(fur position) / d(uv) from screen derivatives: both are affine over a triangle
    vec3 dpdx = dFdx(fur_position);
    vec3 dpdy = dFdy(fur_position);
    vec2 dudx = dFdx(uv);
    vec2 dudy = dFdy(uv);
    float det = dudx.x * dudy.y - dudy.x * dudx.y;
    vec3 dpdu = abs(det) > 1e-12 ? (dpdx * dudy.y - dpdy * dudx.y) / det : vec3(0.0);
    vec3 dpdv = abs(det) > 1e-12 ? (dpdy * dudx.x - dpdx * dudy.x) / det : vec3(0.0);
    vec2 d = vec2(0.0);
    bool kept = skin || clump_fur(uv, h, d);  // the skin under the fur does not clump
    FurLayer layer;
    layer.color_uv = uv + d;
    layer.fur_position = fur_position + dpdu * d.x + dpdv * d.y;
    layer.kept = kept;
    return layer;
}
