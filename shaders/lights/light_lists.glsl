// Per-tile or per-cluster light lists (deferred.light_lists): the tiled and clustered light
// paths and Forward+. A list holds the volume lights that can touch its tile or cluster (the
// full-screen ones, [0, u_global_light_count), apply to every pixel). The culling shaders write
// each list twice:
// - in a storage buffer of light indices: a count per list, then capacity slots per list
//   (the coarse tiles' lists, which the tiled culling's second dispatch reads, live there only);
// - for the shading, in u_light_list_texture, an RGBA32F texture of two texels a slot, 2^
//   u_list_row_shift texels a row (lights/light_list_writer.glsl): the light's sphere
//   (position.xyz, radius) and its colour (rgb; w = type id + 256 x its index in the light
//   buffer, exact in a float). The first texel of a list's count slot holds its count in x.
//   The shading loop reads one texel a listed light, and one more for each that reaches the
//   pixel, where a list of indices cost the index, the sphere and the colour (lights.toml at
//   1024 lights, 640x360: the tiled shading 62-67 -> 51-58 ms, benchmarks/README.md).
layout(std430, binding = 1) buffer LightLists {
    uint light_list_data[];
};
uniform sampler2D u_light_list_texture;
uniform int u_list_row_shift;   // log2 of the texture's texels per row

uniform int u_list_base;        // culling: the word where its lists begin (the shading's: 0)
uniform int u_list_count;       // lists: tiles, or tiles x depth slices
uniform int u_list_capacity;    // slots per list
uniform ivec3 u_list_grid;      // tiles across, tiles down, depth slices (1 when tiled)
uniform int u_list_tile;        // pixels per tile side
uniform vec2 u_list_depth;      // clustered: near plane, slices / log(far / near)

int light_list_slice(float depth) {
    float slice = log(max(depth, u_list_depth.x) / u_list_depth.x) * u_list_depth.y;
    return clamp(int(floor(slice)), 0, u_list_grid.z - 1);
}

// The list of the pixel (and linear view depth, when clustered).
int light_list_of(ivec2 pixel, float depth) {
    ivec2 tile = min(pixel / u_list_tile, u_list_grid.xy - 1);
#ifdef LIGHT_LISTS_CLUSTERED
    return (light_list_slice(depth) * u_list_grid.y + tile.y) * u_list_grid.x + tile.x;
#else
    return tile.y * u_list_grid.x + tile.x;
#endif
}

// The shading texture's first texel of a slot (the second is the next one: SLOT_TEXELS in
// deferred.light_lists).
ivec2 light_list_texel(int slot) {
    int texel = 2 * slot;
    return ivec2(texel & ((1 << u_list_row_shift) - 1), texel >> u_list_row_shift);
}

int light_list_length(int list) {
    return min(int(texelFetch(u_light_list_texture, light_list_texel(list), 0).x),
               u_list_capacity);
}

// The slot of a list's first light (its count at slot u_list_base + list, then every list's
// slots).
int light_list_first_slot(int list) {
    return u_list_base + u_list_count + list * u_list_capacity;
}

// A listed light's bounding sphere: view-space centre, radius (deferred.light: volume "sphere").
vec4 listed_light_sphere(int slot) {
    return texelFetch(u_light_list_texture, light_list_texel(slot), 0);
}

// Its whole record: the colour and type from the list, the sphere (its position texel) as read,
// the direction and extra texels from the light buffer (types that use them: a shader of
// point lights only never reads them).
LightRecord listed_light_record(int slot, vec4 sphere) {
    vec4 color = texelFetch(u_light_list_texture, light_list_texel(slot) + ivec2(1, 0), 0);
    int code = int(color.w);
    LightRecord record = fetch_light(code >> 8);  // only what the light's type reads is read
    return LightRecord(vec4(color.rgb, float(code & 255)), sphere, record.direction,
                       record.extra);
}
