// Per-tile or per-cluster light lists (deferred.light_lists): the tiled and clustered light
// paths and Forward+. One storage buffer: a count per list, then each list's light indices
// (capacity slots per list; indices into the light buffer, volume lights only - the full-screen
// ones, [0, u_global_light_count), apply to every pixel). The culling shaders write it; the
// shading passes read its copy in u_light_list_texture, 2^u_list_row_shift words a row.
layout(std430, binding = 1) buffer LightLists {
    uint light_list_data[];
};
uniform usampler2D u_light_list_texture;
uniform int u_list_row_shift;   // log2 of the texture's words per row

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

uint light_list_word(int i) {
    return texelFetch(u_light_list_texture,
                      ivec2(i & ((1 << u_list_row_shift) - 1), i >> u_list_row_shift), 0).r;
}

int light_list_length(int list) {
    return min(int(light_list_word(list)), u_list_capacity);
}

// The word of a list's first slot (its counts at u_list_base + list, then every list's slots).
int light_list_first_slot(int list) {
    return u_list_base + u_list_count + list * u_list_capacity;
}

int light_list_light(int list, int k) {
    return int(light_list_word(light_list_first_slot(list) + k));
}

// Whether the volume light `index` reaches view-space point P: its record's position is the
// bounding sphere (deferred.light: volume "sphere"). A list holds the lights that touch the
// tile or cluster; most miss any one pixel of it, and this test is far cheaper than the light.
bool light_reaches(int index, vec3 P) {
    vec4 sphere = fetch_light_sphere(index);
    vec3 to_light = sphere.xyz - P;
    return dot(to_light, to_light) <= sphere.w * sphere.w;
}
