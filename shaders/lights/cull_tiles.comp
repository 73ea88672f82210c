// Tiled light culling (Andersson 2009, Olsson and Assarsson 2011): each 16x16 tile's depth
// bounds in the linear depth and the view-space box of its points, then every volume light's
// sphere tested against the tile's frustum (four side planes through the eye, and the depth
// bounds) and the box; the ones that touch both are appended to the tile's list. The box
// matters where a tile holds a slanted surface or two at different depths: the frustum between
// the depth bounds is then far larger than the points.
// CULL_FROM_NEAR (Forward+): the bounds run from the near plane to the farthest depth, or to the
// far plane on tiles of background, since blended surfaces (fur shells) lie in front of it;
// there is no box.
// It runs twice (deferred.light_lists): over coarse tiles of 4x4 tiles (CULL_COARSE) against
// every light, then over the tiles against their coarse tile's list only (CULL_CANDIDATES):
// at 1024 lights and 1280x720, 3600 tiles each testing every light cost 15-22 ms, the two
// dispatches 8.6-9.2 ms.
// An invocation per tile, looping the tile's pixels and then every light in order: the lists
// come out in light order whatever the scheduling (the same image every frame, on any driver),
// and no invocation waits on another. A work group per tile (its invocations reducing the
// bounds with shared atomics, then sharing out the lights), as before, cost 4-5x as much on
// llvmpipe, where a work group's invocations are SIMD lanes looped over on one CPU thread and
// each barrier and shared atomic is a pass over them.
layout(local_size_x = CULL_GROUP_SIZE) in;  // deferred.light_lists

#include "common/light_buffer.glsl"
#include "lights/light_lists.glsl"
#include "lights/tile_frustum.glsl"
#include "lights/light_list_writer.glsl"

uniform sampler2D u_linear_depth;
uniform vec2 u_near_far;
uniform vec4 u_pixel_to_view;  // view xy / linear depth = pixel * .xy + .zw (pixel_to_view)
uniform int u_global_light_count;
#ifdef CULL_CANDIDATES
// The coarse lists (deferred.light_lists: a first dispatch over tiles of u_candidate_ratio x
// u_candidate_ratio tiles): a tile tests only its coarse tile's lights, which hold every light
// that can touch it, in light order (the coarse tile's frustum, depth bounds and box hold the
// tile's), instead of every light.
uniform int u_candidate_base;     // where the coarse lists begin
uniform int u_candidate_count;    // coarse lists
uniform int u_candidate_columns;  // coarse tiles across
uniform int u_candidate_ratio;    // tiles per coarse tile side
#endif

// The tile's depth bounds and the box of its points, as main gathers them.
float low_depth, high_depth;
vec2 low_xy, high_xy;

void take_pixel(float depth, ivec2 pixel, bool inside) {
    if (inside && depth > 0.0) {
        low_depth = min(low_depth, depth);
        high_depth = max(high_depth, depth);
        vec2 point = depth * ((vec2(pixel) + 0.5) * u_pixel_to_view.xy +
                              u_pixel_to_view.zw);  // the lighting's view_position
        low_xy = min(low_xy, point);
        high_xy = max(high_xy, point);
    }
}

void main() {
    int list = int(gl_GlobalInvocationID.x);
    if (list >= u_list_grid.x * u_list_grid.y) return;
    ivec2 tile = ivec2(list % u_list_grid.x, list / u_list_grid.x);
    ivec2 origin = tile * u_list_tile;
    ivec2 end = min(origin + u_list_tile, ivec2(u_resolution));
    // the tile's depth bounds and the view-space box of its points, a 2x2 block of pixels a
    // fetch (textureGather: a quarter of the fetches of one texel each)
    low_depth = uintBitsToFloat(0x7f7fffffu);  // the largest float
    high_depth = 0.0;
    low_xy = vec2(low_depth);
    high_xy = -low_xy;
    vec2 texel = 1.0 / u_resolution;
    for (int y = origin.y; y < end.y; y += 2) {
        for (int x = origin.x; x < end.x; x += 2) {
            // the corner shared by pixels (x, y) .. (x + 1, y + 1): .w (x, y), .z (x + 1, y),
            // .x (x, y + 1), .y (x + 1, y + 1)
            vec4 depths = textureGather(u_linear_depth, vec2(x + 1, y + 1) * texel, 0);
            bool right = x + 1 < end.x, up = y + 1 < end.y;  // a tile of odd width or height
            take_pixel(depths.w, ivec2(x, y), true);
            take_pixel(depths.z, ivec2(x + 1, y), right);
            take_pixel(depths.x, ivec2(x, y + 1), up);
            take_pixel(depths.y, ivec2(x + 1, y + 1), right && up);
        }
    }
    bool empty = high_depth <= 0.0;
    float near_depth = low_depth;
    float far_depth = high_depth;
#ifdef CULL_FROM_NEAR
    near_depth = u_near_far.x;
#ifdef CULL_COARSE
    far_depth = u_near_far.y;  // its tiles of background reach the far plane
#else
    far_depth = empty ? u_near_far.y : high_depth;
#endif
    empty = false;
#endif
    int count = 0;
    if (!empty) {
        vec3 planes[4];
        tile_planes(origin, end, planes);
#ifndef CULL_FROM_NEAR
        // The box of the tile's points in view space: where the tile holds one surface, far
        // tighter than its frustum between the depth bounds (lights.toml: 27% fewer entries).
        // Padded by 1e-4 of the depth: the lighting finds its points through the inverse
        // projection, the box through pixel_to_view; they may differ in the last bits.
        float pad = 1e-4 * far_depth;
        vec3 box_low = vec3(low_xy, -far_depth) - pad;
        vec3 box_high = vec3(high_xy, -near_depth) + pad;
#endif
        int slots = light_list_first_slot(list);
#ifdef CULL_CANDIDATES
        int coarse = (tile.y / u_candidate_ratio) * u_candidate_columns +
                     tile.x / u_candidate_ratio;
        int candidates = min(int(light_list_data[u_candidate_base + coarse]), u_list_capacity);
        int candidate_slots = u_candidate_base + u_candidate_count + coarse * u_list_capacity;
        for (int i = 0; i < candidates; ++i) {
            int index = int(light_list_data[candidate_slots + i]);
#else
        int local_count = u_light_count - u_global_light_count;
        for (int i = 0; i < local_count; ++i) {
            int index = u_global_light_count + i;
#endif
            vec4 sphere = fetch_light_sphere(index);
            float z = -sphere.z;
            if (z + sphere.w < near_depth || z - sphere.w > far_depth) continue;
            if (!sphere_touches_planes(planes, sphere)) continue;
#ifndef CULL_FROM_NEAR
            vec3 outside = sphere.xyz - clamp(sphere.xyz, box_low, box_high);
            if (dot(outside, outside) > sphere.w * sphere.w) continue;
#endif
            if (count < u_list_capacity) light_list_write(slots + count, index, sphere);
            ++count;
        }
    }
    light_list_write_count(list, count);
}
