// Tiled light culling (Andersson 2009, Olsson and Assarsson 2011): each 16x16 tile's depth
// bounds in the linear depth and the view-space box of its points, then every volume light's
// sphere tested against the tile's frustum (four side planes through the eye, and the depth
// bounds) and the box; the ones that touch both are appended to the tile's list. The box
// matters where a tile holds a slanted surface or two at different depths: the frustum between
// the depth bounds is then far larger than the points.
// CULL_FROM_NEAR (Forward+): the bounds run from the near plane to the farthest depth, or to the
// far plane on tiles of background, since blended surfaces (fur shells) lie in front of it;
// there is no box.
// It runs twice (deferred.lighting.culling): over coarse tiles of 4x4 tiles (CULL_COARSE) against
// every light, then over the tiles against their coarse tile's list only (CULL_CANDIDATES),
// about half the time of every tile testing every light (benchmarks/README.md). The second writes the lists of each tile's four 8x8 quadrants
// (LIST_QUADRANTS, below).
// An invocation per tile, looping the tile's pixels and then every light in order: the lists
// come out in light order whatever the scheduling (the same image every frame, on any driver),
// and no invocation waits on another. A work group per tile (its invocations reducing the
// bounds with shared atomics, then sharing out the lights), as before, cost several times as
// much on llvmpipe, where a work group's invocations are SIMD lanes looped over on one CPU thread and
// each barrier and shared atomic is a pass over them.
layout(local_size_x = CULL_GROUP_SIZE) in;  // deferred.lighting.lists

#include "common/light_buffer.glsl"
#include "lighting/light_lists.glsl"
#include "lighting/tile_frustum.glsl"
#include "lighting/light_list_writer.glsl"

uniform sampler2D u_linear_depth;
uniform vec2 u_near_far;
uniform vec4 u_pixel_to_view;  // view xy / linear depth = pixel * .xy + .zw (pixel_to_view)
uniform int u_global_light_count;
#ifdef CULL_CANDIDATES
// The coarse lists (deferred.lighting.lists: a first dispatch over tiles of u_candidate_ratio x
// u_candidate_ratio tiles): a tile tests only its coarse tile's lights, which hold every light
// that can touch it, in light order (the coarse tile's frustum, depth bounds and box hold the
// tile's), instead of every light.
uniform int u_candidate_base;     // where the coarse lists begin
uniform int u_candidate_count;    // coarse lists
uniform int u_candidate_columns;  // coarse tiles across
uniform int u_candidate_ratio;    // tiles per coarse tile side
uniform int u_candidate_capacity; // slots per coarse list
#endif

// LIST_QUADRANTS (the second dispatch): a tile's lists are those of its four 8x8 quadrants
// (deferred.lighting.lists.LIST_SPLIT), each with its own side planes, depth bounds and box. A
// light is tested against the whole tile first, and only where it touches it against the
// quadrants, all four at once in the lanes of a vec4. lights.toml at 1024 lights, 640x360: the
// shading loops 21.6 entries a pixel instead of 31.5, for a dearer culling, most of it the
// more numerous writes (benchmarks/README.md).
// Indexing the quadrants' data with a variable (an array of structs, a loop over the lanes)
// made the culling slower on llvmpipe, which keeps such arrays in memory.

// A tile's (or quadrant's) depth bounds and the view-space box of its points.
struct TileBounds {
    float low_depth, high_depth;
    vec2 low_xy, high_xy;
};

void take_pixel(inout TileBounds b, float depth, ivec2 pixel, bool inside) {
    if (inside && depth > 0.0) {
        b.low_depth = min(b.low_depth, depth);
        b.high_depth = max(b.high_depth, depth);
        vec2 point = depth * ((vec2(pixel) + 0.5) * u_pixel_to_view.xy +
                              u_pixel_to_view.zw);  // the lighting's view_position
        b.low_xy = min(b.low_xy, point);
        b.high_xy = max(b.high_xy, point);
    }
}

const float LARGEST = uintBitsToFloat(0x7f7fffffu);

TileBounds no_points() {
    return TileBounds(LARGEST, 0.0, vec2(LARGEST), vec2(-LARGEST));
}

// The bounds of the pixels [origin, end), a 2x2 block of pixels a fetch (textureGather: a
// quarter of the fetches of one texel each).
TileBounds gather_bounds(ivec2 origin, ivec2 end) {
    TileBounds b = no_points();
    vec2 texel = 1.0 / u_resolution;
    for (int y = origin.y; y < end.y; y += 2) {
        for (int x = origin.x; x < end.x; x += 2) {
            // the corner shared by pixels (x, y) .. (x + 1, y + 1): .w (x, y), .z (x + 1, y),
            // .x (x, y + 1), .y (x + 1, y + 1)
            vec4 depths = textureGather(u_linear_depth, vec2(x + 1, y + 1) * texel, 0);
            bool right = x + 1 < end.x, up = y + 1 < end.y;  // a tile of odd width or height
            take_pixel(b, depths.w, ivec2(x, y), true);
            take_pixel(b, depths.z, ivec2(x + 1, y), right);
            take_pixel(b, depths.x, ivec2(x, y + 1), up);
            take_pixel(b, depths.y, ivec2(x + 1, y + 1), right && up);
        }
    }
    return b;
}

TileBounds bounds_union(TileBounds a, TileBounds b) {
    return TileBounds(min(a.low_depth, b.low_depth), max(a.high_depth, b.high_depth),
                      min(a.low_xy, b.low_xy), max(a.high_xy, b.high_xy));
}

// The depth range a light is tested against: the points' (CULL_FROM_NEAR: from the near
// plane to the farthest point, or to the far plane where there is none).
vec2 depth_range(TileBounds b) {
#ifdef CULL_FROM_NEAR
#ifdef CULL_COARSE
    return u_near_far;  // its tiles of background reach the far plane
#else
    return vec2(u_near_far.x, b.high_depth <= 0.0 ? u_near_far.y : b.high_depth);
#endif
#else
    return vec2(b.low_depth, b.high_depth);
#endif
}

// What a light is tested against: the frustum's side planes, the depth range, and (not
// CULL_FROM_NEAR) the box of the points.
struct TileVolume {
    vec3 planes[4];
    vec2 depth;
    vec3 box_low, box_high;
    bool empty;
};

// The box of the points in view space, over their depth range: where a tile holds one
// surface, far tighter than its frustum between the depth bounds (lights.toml: 27% fewer
// entries). Padded by 1e-4 of the depth: the lighting finds its points through the inverse
// projection, the box through pixel_to_view; they may differ in the last bits.
void padded_box(TileBounds b, vec2 depth, out vec3 low, out vec3 high) {
    float pad = 1e-4 * depth.y;
    low = vec3(b.low_xy, -depth.y) - pad;
    high = vec3(b.high_xy, -depth.x) + pad;
}

TileVolume tile_volume(ivec2 origin, ivec2 end, TileBounds b) {
    TileVolume v;
#ifdef CULL_FROM_NEAR
    v.empty = false;
#else
    v.empty = b.high_depth <= 0.0;
#endif
    v.depth = depth_range(b);
    tile_planes(origin, end, v.planes);
    padded_box(b, v.depth, v.box_low, v.box_high);
    return v;
}

bool sphere_touches_volume(TileVolume v, vec4 sphere) {
    float z = -sphere.z;
    if (z + sphere.w < v.depth.x || z - sphere.w > v.depth.y) return false;
    if (!sphere_touches_planes(v.planes, sphere)) return false;
#ifndef CULL_FROM_NEAR
    vec3 outside = sphere.xyz - clamp(sphere.xyz, v.box_low, v.box_high);
    if (dot(outside, outside) > sphere.w * sphere.w) return false;
#endif
    return true;
}

#ifdef LIST_QUADRANTS
// A tile's quadrants, one a lane: x bottom left, y bottom right, z top left, w top right.
// Their side planes are the tile's three column edges and three row edges (normals toward
// growing pixels); an absent quadrant (past the grid, or no points) has an empty depth range.
struct Quadrants {
    vec3 columns[3], rows[3];
    vec4 near_depth, far_depth;
    vec4 low_x, low_y, low_z, high_x, high_y, high_z;  // the boxes (not CULL_FROM_NEAR)
};

// The plane through the eye and the pixel edge at `edge` on `axis` (0: a column edge), its
// normal toward growing pixels; `span` the tile's pixel range on the other axis.
vec3 edge_plane(int axis, float edge, vec2 span) {
    vec2 a = axis == 0 ? vec2(edge, span.x) : vec2(span.x, edge);
    vec2 b = axis == 0 ? vec2(edge, span.y) : vec2(span.y, edge);
    vec2 inside = 0.5 * (a + b);
    inside[axis] += 0.5;
    vec3 normal = normalize(cross(view_ray(a), view_ray(b)));
    return dot(normal, view_ray(inside)) < 0.0 ? -normal : normal;
}

void set_quadrant(inout Quadrants q, int lane, TileBounds b, bool present) {
    vec2 depth = depth_range(b);
#ifndef CULL_FROM_NEAR
    present = present && b.high_depth > 0.0;
    vec3 low, high;
    padded_box(b, depth, low, high);
    q.low_x[lane] = low.x;
    q.low_y[lane] = low.y;
    q.low_z[lane] = low.z;
    q.high_x[lane] = high.x;
    q.high_y[lane] = high.y;
    q.high_z[lane] = high.z;
#endif
    q.near_depth[lane] = present ? depth.x : LARGEST;
    q.far_depth[lane] = present ? depth.y : -LARGEST;
}

// Which quadrants the sphere touches: the tests of sphere_touches_volume, four lanes at once.
bvec4 quadrants_touched(Quadrants q, vec4 sphere) {
    float r = sphere.w;
    vec3 d_columns = vec3(dot(q.columns[0], sphere.xyz), dot(q.columns[1], sphere.xyz),
                          dot(q.columns[2], sphere.xyz));
    vec3 d_rows = vec3(dot(q.rows[0], sphere.xyz), dot(q.rows[1], sphere.xyz),
                       dot(q.rows[2], sphere.xyz));
    // inside a quadrant's low edge (distance >= -r) and its high edge (distance <= r)
    vec4 margin = min(d_columns.xyxy + r, r - d_columns.yzyz);
    margin = min(margin, min(d_rows.xxyy + r, r - d_rows.yyzz));
    float z = -sphere.z;
    margin = min(margin, min(z + r - q.near_depth, q.far_depth - (z - r)));
#ifndef CULL_FROM_NEAR
    vec4 ox = sphere.x - clamp(vec4(sphere.x), q.low_x, q.high_x);
    vec4 oy = sphere.y - clamp(vec4(sphere.y), q.low_y, q.high_y);
    vec4 oz = sphere.z - clamp(vec4(sphere.z), q.low_z, q.high_z);
    margin = min(margin, r * r - (ox * ox + oy * oy + oz * oz));
#endif
    return greaterThanEqual(margin, vec4(0.0));
}

// Quadrant `lane` of the tile [origin, end): its list (-1 past the grid), its bounds in q and
// in the tile's.
void add_quadrant(inout Quadrants q, inout ivec4 lists, inout TileBounds whole, int lane,
                  ivec2 origin, ivec2 middle, ivec2 end) {
    ivec2 side = ivec2(lane & 1, lane >> 1);  // 0: the low half, 1: the high one
    ivec2 list = (origin / u_list_tile) + side;
    bool present = all(lessThan(list, u_list_grid.xy));
    TileBounds b = present ? gather_bounds(origin + side * (middle - origin),
                                           middle + side * (end - middle)) : no_points();
    lists[lane] = present ? list.y * u_list_grid.x + list.x : -1;
    set_quadrant(q, lane, b, present);
    whole = bounds_union(whole, b);
}
#endif

void append(int first_slot, inout int count, int index, vec4 sphere) {
    if (count < u_list_capacity) light_list_write(first_slot + count, index, sphere);
    ++count;
}

void main() {
#ifdef LIST_QUADRANTS
    ivec2 tiles = (u_list_grid.xy + 1) / 2;  // a tile is 2x2 lists
#else
    ivec2 tiles = u_list_grid.xy;
#endif
    int tile_index = int(gl_GlobalInvocationID.x);
    if (tile_index >= tiles.x * tiles.y) return;
    ivec2 tile = ivec2(tile_index % tiles.x, tile_index / tiles.x);
    ivec2 resolution = ivec2(u_resolution);
#ifdef LIST_QUADRANTS
    int list_tile = u_list_tile;
    ivec2 origin = tile * 2 * list_tile;
    ivec2 end = min(origin + 2 * list_tile, resolution);
    ivec2 middle = min(origin + list_tile, resolution);
    // the quadrants' lists (-1 past the grid) and bounds
    ivec4 lists;
    Quadrants q;
    TileBounds whole = no_points();
    // each quadrant by hand: a loop over the lanes left q in memory (indexed by a variable)
    add_quadrant(q, lists, whole, 0, origin, middle, end);
    add_quadrant(q, lists, whole, 1, origin, middle, end);
    add_quadrant(q, lists, whole, 2, origin, middle, end);
    add_quadrant(q, lists, whole, 3, origin, middle, end);
    vec2 span_x = vec2(origin.x, end.x), span_y = vec2(origin.y, end.y);
    q.columns[0] = edge_plane(0, float(origin.x), span_y);
    q.columns[1] = edge_plane(0, float(middle.x), span_y);
    q.columns[2] = edge_plane(0, float(end.x), span_y);
    q.rows[0] = edge_plane(1, float(origin.y), span_x);
    q.rows[1] = edge_plane(1, float(middle.y), span_x);
    q.rows[2] = edge_plane(1, float(end.y), span_x);
    ivec4 slots = ivec4(light_list_first_slot(lists.x), light_list_first_slot(lists.y),
                        light_list_first_slot(lists.z), light_list_first_slot(lists.w));
    ivec4 counts = ivec4(0);
#else
    ivec2 origin = tile * u_list_tile;
    ivec2 end = min(origin + u_list_tile, resolution);
    TileBounds whole = gather_bounds(origin, end);
    int slot = light_list_first_slot(tile_index);
    int count = 0;
#endif
    TileVolume volume = tile_volume(origin, end, whole);
#if defined(LIST_QUADRANTS) && defined(CULL_FROM_NEAR)
    // a quadrant of background reaches the far plane (blended surfaces may lie anywhere in
    // front of it): so does the tile the quadrants are tested within
    volume.depth.y = max(max(q.far_depth.x, q.far_depth.y), max(q.far_depth.z, q.far_depth.w));
#endif
    if (!volume.empty) {
#ifdef CULL_CANDIDATES
        int coarse = (tile.y / u_candidate_ratio) * u_candidate_columns +
                     tile.x / u_candidate_ratio;
        int candidates = min(int(light_list_data[u_candidate_base + coarse]),
                             u_candidate_capacity);
        int candidate_slots = u_candidate_base + u_candidate_count +
                              coarse * u_candidate_capacity;
        for (int i = 0; i < candidates; ++i) {
            int index = int(light_list_data[candidate_slots + i]);
#else
        int local_count = u_light_count - u_global_light_count;
        for (int i = 0; i < local_count; ++i) {
            int index = u_global_light_count + i;
#endif
            vec4 sphere = fetch_light_sphere(index);
            if (!sphere_touches_volume(volume, sphere)) continue;
#ifdef LIST_QUADRANTS
            bvec4 touched = quadrants_touched(q, sphere);
            if (!any(touched)) continue;
            ivec4 at = slots + counts;  // each quadrant's next slot
            ivec4 held = counts;
            counts += ivec4(touched);
            // one write a touched quadrant, in a loop over their bits: a block of SIMD lanes
            // runs as many writes as its lane touching the most quadrants, where four `if`s
            // ran each one any lane needed (benchmarks/README.md)
            uint quadrants = uint(touched.x) | uint(touched.y) << 1 | uint(touched.z) << 2 |
                             uint(touched.w) << 3;
            while (quadrants != 0u) {
                int lane = findLSB(quadrants);
                quadrants &= quadrants - 1u;
                if (held[lane] < u_list_capacity) light_list_write(at[lane], index, sphere);
            }
#else
            append(slot, count, index, sphere);
#endif
        }
    }
#ifdef LIST_QUADRANTS
    if (lists.x >= 0) light_list_write_count(lists.x, counts.x);
    if (lists.y >= 0) light_list_write_count(lists.y, counts.y);
    if (lists.z >= 0) light_list_write_count(lists.z, counts.z);
    if (lists.w >= 0) light_list_write_count(lists.w, counts.w);
#else
    light_list_write_count(tile_index, count);
#endif
}
