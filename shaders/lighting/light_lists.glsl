// Per-tile or per-cluster light lists (deferred.lighting.lists): the tiled and clustered light
// paths and Forward+. A list holds the volume lights that can touch its tile or cluster (the
// full-screen ones, [0, u_global_light_count), apply to every pixel). The culling shaders
// (lighting/light_list_writer.glsl) write:
// - in a storage buffer: a count per list, then (tiled) the coarse tiles' lists of light
//   indices, which the tiled culling's second dispatch reads;
// - for the shading, in u_light_list_texture, an RGBA32UI texture of one texel a slot, 2^
//   u_list_row_shift texels a row: each list's count (in the x of its count slot), and each
//   listed light's sphere, its position's three floats and, in w, its index in the light
//   buffer (high 16 bits) and its radius as a half float rounded up (low 16 bits).
//   The shading loop reads one texel a listed light, and the light's colour (and, for the
//   types that read them, the rest of its record) from the light buffer for each that reaches
//   the pixel, where a list of indices cost the index, the sphere and the colour
//   (benchmarks/README.md).
layout(std430, binding = 1) buffer LightLists {
    uint light_list_data[];
};
uniform usampler2D u_light_list_texture;
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

// The shading texture's texel of a slot (SLOT_TEXELS in deferred.lighting.lists).
ivec2 light_list_texel(int slot) {
    return ivec2(slot & ((1 << u_list_row_shift) - 1), slot >> u_list_row_shift);
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

// A listed light's slot: its bounding sphere (view-space centre, radius: a light whose volume is
// LightVolume.SPHERE, deferred.interfaces.light) and its index in the light buffer.
struct ListedLight {
    vec4 sphere;
    int index;
};

ListedLight listed_light(int slot) {
    uvec4 texel = texelFetch(u_light_list_texture, light_list_texel(slot), 0);
    return ListedLight(vec4(uintBitsToFloat(texel.xyz), unpackHalf2x16(texel.w).x),
                       int(texel.w >> 16));
}

// Whether the listed light's sphere holds P (the shading's test before evaluating it).
bool listed_light_reaches(ListedLight listed, vec3 P) {
    vec3 to_light = listed.sphere.xyz - P;
    return dot(to_light, to_light) <= listed.sphere.w * listed.sphere.w;
}

// Its whole record: the light buffer's (only what the light's type reads is read), with the
// sphere as listed. Its radius is a half float rounded up, so a light's window reaches 0 up
// to 2^-10 of the radius further out than on the volumes and naive paths (PSNR 61 dB at 1024
// lights, 1280x720): the exact radius would cost a fetch more for every light that reaches.
LightRecord listed_light_record(ListedLight listed) {
    LightRecord record = fetch_light(listed.index);
    record.position = listed.sphere;
    return record;
}
