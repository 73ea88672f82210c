// The culling shaders' writes of a list (lights/light_lists.glsl has the layout): the light
// index in the storage buffer, and, for the lists the shading reads (all but CULL_COARSE's),
// the light's sphere and colour in the shading's texture, bound as an image.
#ifndef CULL_COARSE
layout(rgba32f) uniform writeonly image2D u_light_list_image;  // at light_list_texel(slot)
#endif

// The light `index` into `slot`: its sphere (as the culling read it) and, in the shading's
// copy, its colour texel with w = type id + 256 x index (exact in a float below 2^24).
void light_list_write(int slot, int index, vec4 sphere) {
    light_list_data[slot] = uint(index);
#ifndef CULL_COARSE
    ivec2 texel = light_list_texel(slot);
    vec4 color = fetch_light(index).color;
    imageStore(u_light_list_image, texel, sphere);
    imageStore(u_light_list_image, texel + ivec2(1, 0),
               vec4(color.rgb, color.w + 256.0 * float(index)));
#endif
}

void light_list_write_count(int list, int count) {
    light_list_data[u_list_base + list] = uint(count);
#ifndef CULL_COARSE
    imageStore(u_light_list_image, light_list_texel(u_list_base + list),
               vec4(float(count), 0.0, 0.0, 0.0));
#endif
}
