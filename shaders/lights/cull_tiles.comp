// Tiled light culling (Andersson 2009, Olsson and Assarsson 2011): a work group per 16x16 tile
// finds the tile's depth bounds in the linear depth and the view-space box of its points, then
// its threads test every volume light's sphere against the tile's frustum (four side planes
// through the eye, and the depth bounds) and the box, and append the ones that touch both to
// the tile's list. The box matters where a tile holds a slanted surface or two at different
// depths: the frustum between the depth bounds is then far larger than the points.
// CULL_FROM_NEAR (Forward+): the bounds run from the near plane to the farthest depth, or to the
// far plane on tiles of background, since blended surfaces (fur shells) lie in front of it;
// there is no box.
// 64 invocations, each reducing a column of 4 pixels of the tile first: on llvmpipe, where
// invocations are SIMD lanes looped over on the CPU, a quarter of the invocations and of the
// shared-memory atomics make the pass about twice as fast as one invocation per pixel.
#define TILE_ROWS_PER_INVOCATION 4
layout(local_size_x = 16, local_size_y = 4) in;
const int INVOCATIONS = 64;

#include "common/light_buffer.glsl"
#include "lights/light_lists.glsl"

uniform sampler2D u_linear_depth;
uniform mat4 u_inverse_projection;
uniform vec2 u_resolution;
uniform vec2 u_near_far;
uniform vec4 u_pixel_to_view;  // view xy / linear depth = pixel * .xy + .zw (pixel_to_view)
uniform int u_global_light_count;

shared uint s_min_bits;
shared uint s_max_bits;
shared uint s_low_xy[2];   // the view-space box of the tile's points, x and y (ordered bits)
shared uint s_high_xy[2];
shared float s_near_depth;
shared float s_far_depth;
shared bool s_empty;
shared vec3 s_planes[4];
shared uint s_count;

// Floats as uints that order as the floats do, negative ones too (atomicMin / atomicMax).
uint ordered_bits(float value) {
    uint bits = floatBitsToUint(value);
    return (bits & 0x80000000u) != 0u ? ~bits : bits | 0x80000000u;
}

float from_ordered_bits(uint bits) {
    return uintBitsToFloat((bits & 0x80000000u) != 0u ? bits & 0x7fffffffu : ~bits);
}

vec3 view_ray(vec2 pixel) {
    vec2 ndc = pixel / u_resolution * 2.0 - 1.0;
    vec4 ray = u_inverse_projection * vec4(ndc, 1.0, 1.0);
    return ray.xyz / ray.w;
}

void main() {
    ivec2 tile = ivec2(gl_WorkGroupID.xy);
    int list = tile.y * u_list_grid.x + tile.x;
    if (gl_LocalInvocationIndex == 0u) {
        s_min_bits = 0x7f7fffffu;  // the largest float's bits: positive floats order as uints
        s_max_bits = 0u;
        s_low_xy[0] = s_low_xy[1] = 0xffffffffu;
        s_high_xy[0] = s_high_xy[1] = 0u;
    }
    barrier();
    float low_depth = uintBitsToFloat(0x7f7fffffu);
    float high_depth = 0.0;
    vec2 low_xy = vec2(uintBitsToFloat(0x7f7fffffu));
    vec2 high_xy = -low_xy;
    for (int row = 0; row < TILE_ROWS_PER_INVOCATION; ++row) {
        ivec2 row_pixel = ivec2(gl_LocalInvocationID.xy) +
                          ivec2(0, int(gl_WorkGroupSize.y) * row);
        ivec2 pixel = tile * u_list_tile + row_pixel;
        if (all(lessThan(pixel, ivec2(u_resolution)))) {
            float depth = texelFetch(u_linear_depth, pixel, 0).r;
            if (depth > 0.0) {
                low_depth = min(low_depth, depth);
                high_depth = max(high_depth, depth);
                vec2 point = depth * ((vec2(pixel) + 0.5) * u_pixel_to_view.xy +
                                      u_pixel_to_view.zw);  // the lighting's view_position
                low_xy = min(low_xy, point);
                high_xy = max(high_xy, point);
            }
        }
    }
    if (high_depth > 0.0) {
        atomicMin(s_min_bits, floatBitsToUint(low_depth));
        atomicMax(s_max_bits, floatBitsToUint(high_depth));
#ifndef CULL_FROM_NEAR
        atomicMin(s_low_xy[0], ordered_bits(low_xy.x));
        atomicMin(s_low_xy[1], ordered_bits(low_xy.y));
        atomicMax(s_high_xy[0], ordered_bits(high_xy.x));
        atomicMax(s_high_xy[1], ordered_bits(high_xy.y));
#endif
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        // One invocation sets the tile's bounds and planes up for all: invocations are SIMD
        // lanes of a loop where compute runs on the CPU (llvmpipe).
        float low = uintBitsToFloat(s_min_bits);
        float high = uintBitsToFloat(s_max_bits);
        ivec2 origin = tile * u_list_tile;
        ivec2 end = min(origin + u_list_tile, ivec2(u_resolution));
        s_empty = high <= 0.0;
        s_near_depth = low;
        s_far_depth = high;
#ifdef CULL_FROM_NEAR
        s_near_depth = u_near_far.x;
        s_far_depth = s_empty ? u_near_far.y : high;
        s_empty = false;
#endif
        // the tile's side planes, through the eye, normals pointing into the tile
        vec2 low_corner = vec2(origin);
        vec2 high_corner = vec2(end);
        vec3 r00 = view_ray(low_corner);
        vec3 r10 = view_ray(vec2(high_corner.x, low_corner.y));
        vec3 r01 = view_ray(vec2(low_corner.x, high_corner.y));
        vec3 r11 = view_ray(high_corner);
        vec3 centre = r00 + r10 + r01 + r11;
        s_planes[0] = normalize(cross(r01, r00));
        s_planes[1] = normalize(cross(r10, r11));
        s_planes[2] = normalize(cross(r00, r10));
        s_planes[3] = normalize(cross(r11, r01));
        for (int k = 0; k < 4; ++k)
            if (dot(s_planes[k], centre) < 0.0) s_planes[k] = -s_planes[k];
        s_count = 0u;
    }
    barrier();
    if (!s_empty) {
        // The tile's bounds in registers: read in the loop, shared memory is read again for
        // every light (the loop's atomics keep the compiler from hoisting the reads), and on
        // llvmpipe each read is a gather over the SIMD lanes.
        float near_depth = s_near_depth;
        float far_depth = s_far_depth;
#ifndef CULL_FROM_NEAR
        // The box of the tile's points in view space: where the tile holds one surface, far
        // tighter than its frustum between the depth bounds (lights.toml: 27% fewer entries).
        // Padded by 1e-4 of the depth: the lighting finds its points through the inverse
        // projection, the box through pixel_to_view; they may differ in the last bits.
        float pad = 1e-4 * far_depth;
        vec3 box_low = vec3(from_ordered_bits(s_low_xy[0]), from_ordered_bits(s_low_xy[1]),
                            -far_depth) - pad;
        vec3 box_high = vec3(from_ordered_bits(s_high_xy[0]), from_ordered_bits(s_high_xy[1]),
                             -near_depth) + pad;
#endif
        vec3 plane0 = s_planes[0], plane1 = s_planes[1], plane2 = s_planes[2], plane3 = s_planes[3];
        int local_count = u_light_count - u_global_light_count;
        for (int i = int(gl_LocalInvocationIndex); i < local_count; i += INVOCATIONS) {
            int index = u_global_light_count + i;
            vec4 sphere = fetch_light_sphere(index);
            float z = -sphere.z;
            if (z + sphere.w < near_depth || z - sphere.w > far_depth) continue;
            if (dot(plane0, sphere.xyz) < -sphere.w || dot(plane1, sphere.xyz) < -sphere.w ||
                dot(plane2, sphere.xyz) < -sphere.w || dot(plane3, sphere.xyz) < -sphere.w)
                continue;
#ifndef CULL_FROM_NEAR
            vec3 outside = sphere.xyz - clamp(sphere.xyz, box_low, box_high);
            if (dot(outside, outside) > sphere.w * sphere.w) continue;
#endif
            uint slot = atomicAdd(s_count, 1u);
            if (int(slot) < u_list_capacity)
                light_list_data[u_list_count + list * u_list_capacity + int(slot)] = uint(index);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) light_list_data[list] = s_count;
}
