// The culling shaders' writes of a list (lighting/light_lists.glsl has the layout). The lists the
// shading reads (all but CULL_COARSE's) go to the shading's texture, bound as an image: one
// texel a listed light (its sphere and index, at light_list_texel(slot)), and the list's count (also in
// the storage buffer, for statistics). The coarse lists, which only the tiled culling's second
// dispatch reads, are light indices in the storage buffer. The fine lists' indices are not
// written there too: the quadrant lists (lighting/cull_tiles.comp) made many more entries, and
// each write is a masked scatter over a SIMD block on llvmpipe (as is each texel of a slot:
// one texel, not two for the sphere and the colour; benchmarks/README.md has the costs).
#ifndef CULL_COARSE
// bound to its unit in the layout: moderngl 5.13 writes no value to an unsigned image uniform
layout(rgba32ui, binding = LIST_IMAGE_UNIT) uniform writeonly uimage2D u_light_list_image;
#endif

// The light `index` into `slot`: the coarse lists' index, or the shading copy's texel of its
// sphere (as the culling read it) and index.
void light_list_write(int slot, int index, vec4 sphere) {
#ifdef CULL_COARSE
    light_list_data[slot] = uint(index);
#else
    // the radius as a half float rounded up, so the shading's sphere test stays conservative
    uint radius = packHalf2x16(vec2(sphere.w, 0.0));
    if (unpackHalf2x16(radius).x < sphere.w) radius += 1u;  // the next half float
    imageStore(u_light_list_image, light_list_texel(slot),
               uvec4(floatBitsToUint(sphere.xyz), (uint(index) << 16) | radius));
#endif
}

void light_list_write_count(int list, int count) {
    light_list_data[u_list_base + list] = uint(count);
#ifndef CULL_COARSE
    imageStore(u_light_list_image, light_list_texel(u_list_base + list), uvec4(count, 0u, 0u, 0u));
#endif
}
