// Exact mode, first half: each glass fragment in front of the opaque scene (the depth test runs
// before the shader: a hidden fragment takes no node) pushes its layer onto its pixel's list.
// Once the pool is full, further fragments are dropped. A helper invocation (a pixel of a 2x2
// quad run for derivatives only) takes no node: its stores are discarded, but a driver may
// still run its atomics, which would link a node that holds nothing.
#extension GL_ARB_ES3_1_compatibility : enable
layout(early_fragment_tests) in;
#include "materials/glass/layer.glsl"
#include "materials/glass/lists.glsl"

uniform int u_glass_capacity;  // nodes in the pool

void main() {
#ifdef GL_ARB_ES3_1_compatibility
    if (gl_HelperInvocation) return;
#endif
    GlassLayer g = glass_layer();
    uint node = atomicAdd(glass_count, 1u) + 1u;
    if (node > uint(u_glass_capacity)) return;
    uint pixel = uint(gl_FragCoord.y) * uint(u_glass_width) + uint(gl_FragCoord.x);
    glass_layers[node - 1u] = uvec4(packHalf2x16(g.emitted.rg),
                                    packHalf2x16(vec2(g.emitted.b, g.coverage.r)),
                                    packHalf2x16(g.coverage.gb), floatBitsToUint(g.depth));
    uint next = atomicExchange(glass_heads[pixel], node);
    glass_links[node - 1u] = uvec2(packHalf2x16(g.offset), next);
}
