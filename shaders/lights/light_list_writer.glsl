// The culling shaders' writes of a list (lights/light_lists.glsl has the layout). The lists the
// shading reads (all but CULL_COARSE's) go to the shading's texture, bound as an image: each
// light's sphere and colour, and the list's count (also in the storage buffer, for statistics).
// The coarse lists, which only the tiled culling's second dispatch reads, are light indices in
// the storage buffer. The fine lists' indices are not written there too: the quadrant lists
// (lights/cull_tiles.comp) made 2.6x as many entries, and each write is a masked scatter over a
// SIMD block on llvmpipe (the culling at 1024 lights, 640x360: 9.0 -> 7.4 ms without them).
#ifndef CULL_COARSE
layout(rgba32f) uniform writeonly image2D u_light_list_image;  // at light_list_texel(slot)
#endif

// The light `index` into `slot`: the coarse lists' index, or the shading copy's sphere (as the
// culling read it) and colour texel (listed_light_color).
void light_list_write(int slot, int index, vec4 sphere, vec4 listed_color) {
#ifdef CULL_COARSE
    light_list_data[slot] = uint(index);
#else
    ivec2 texel = light_list_texel(slot);
    imageStore(u_light_list_image, texel, sphere);
    imageStore(u_light_list_image, texel + ivec2(1, 0), listed_color);
#endif
}

// A light's colour texel in the shading's copy: rgb, w = type id + 256 x index (exact in a
// float below 2^24). Fetched once a light, however many lists it joins.
vec4 listed_light_color(int index) {
#ifdef CULL_COARSE
    return vec4(0.0);  // the coarse lists have no shading copy
#else
    vec4 color = fetch_light(index).color;
    return vec4(color.rgb, color.w + 256.0 * float(index));
#endif
}

void light_list_write_count(int list, int count) {
    light_list_data[u_list_base + list] = uint(count);
#ifndef CULL_COARSE
    imageStore(u_light_list_image, light_list_texel(u_list_base + list),
               vec4(float(count), 0.0, 0.0, 0.0));
#endif
}
