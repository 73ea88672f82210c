// Clustered light assignment (Olsson, Billeter and Assarsson 2012): view-space clusters of
// screen tiles x exponential depth slices. An invocation per tile tests every volume light, in
// order, against the tile's side planes, and appends the ones that touch it to the list of
// every slice their sphere's depth range covers. The invocation owns its tile's lists: no
// atomics, and the lists come out in light order whatever the scheduling, so a frame shades
// its lights in the same order every time (the same image, to the bit). A thread per light
// appending with atomics, as before, gave the lists in the order the threads ran.
layout(local_size_x = CULL_GROUP_SIZE) in;  // deferred.lighting.lists

#include "common/light_buffer.glsl"
#include "lighting/light_lists.glsl"
#include "lighting/tile_frustum.glsl"
#include "lighting/light_list_writer.glsl"

uniform vec2 u_near_far;
uniform int u_global_light_count;

void main() {
    int tiles = u_list_grid.x * u_list_grid.y;
    int tile_index = int(gl_GlobalInvocationID.x);
    if (tile_index >= tiles) return;
    ivec2 tile = ivec2(tile_index % u_list_grid.x, tile_index / u_list_grid.x);
    ivec2 origin = tile * u_list_tile;
    vec3 planes[4];
    tile_planes(origin, min(origin + u_list_tile, ivec2(u_resolution)), planes);
    // the tile's list in slice s is tile_index + s * tiles
    uint counts[LIST_SLICES];
    for (int slice = 0; slice < LIST_SLICES; ++slice) counts[slice] = 0u;
    int local_count = u_light_count - u_global_light_count;
    for (int i = 0; i < local_count; ++i) {
        int index = u_global_light_count + i;
        vec4 sphere = fetch_light_sphere(index);
        float near_depth = -sphere.z - sphere.w;
        float far_depth = -sphere.z + sphere.w;
        if (far_depth < u_near_far.x || near_depth > u_near_far.y) continue;
        if (!sphere_touches_planes(planes, sphere)) continue;
        int last_slice = light_list_slice(far_depth);
        for (int slice = light_list_slice(max(near_depth, u_near_far.x)); slice <= last_slice;
             ++slice) {
            int list = tile_index + slice * tiles;
            uint count = counts[slice];
            if (int(count) < u_list_capacity)
                light_list_write(light_list_first_slot(list) + int(count), index, sphere);
            counts[slice] = count + 1u;
        }
    }
    for (int slice = 0; slice < LIST_SLICES; ++slice)
        light_list_write_count(tile_index + slice * tiles, int(counts[slice]));
}
