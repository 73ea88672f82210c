// Clustered light assignment (Olsson, Billeter and Assarsson 2012): view-space clusters of
// screen tiles x exponential depth slices; a thread per volume light finds the clusters its
// sphere's bounding box covers (tiles from the projected box, slices from its depth range) and
// appends itself to each. The lists' counts are zero when this pass starts.
layout(local_size_x = 64) in;

#include "common/light_buffer.glsl"
#include "lights/light_lists.glsl"

uniform mat4 u_projection;
uniform vec2 u_resolution;
uniform vec2 u_near_far;
uniform int u_global_light_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_light_count - u_global_light_count) return;
    int index = u_global_light_count + i;
    vec4 sphere = fetch_light(index).position;
    float near_depth = -sphere.z - sphere.w;
    float far_depth = -sphere.z + sphere.w;
    if (far_depth < u_near_far.x || near_depth > u_near_far.y) return;
    ivec2 low = ivec2(0);
    ivec2 high = u_list_grid.xy - 1;
    if (near_depth > u_near_far.x) {
        // the projection of the sphere's view-space bounding box (all in front of the eye)
        vec2 ndc_low = vec2(1.0);
        vec2 ndc_high = vec2(-1.0);
        for (int corner = 0; corner < 8; ++corner) {
            vec3 offset = vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1) * 2.0 - 1.0;
            vec4 clip = u_projection * vec4(sphere.xyz + offset * sphere.w, 1.0);
            vec2 ndc = clip.xy / clip.w;
            ndc_low = min(ndc_low, ndc);
            ndc_high = max(ndc_high, ndc);
        }
        if (any(lessThan(ndc_high, vec2(-1.0))) || any(greaterThan(ndc_low, vec2(1.0)))) return;
        vec2 pixel_low = (clamp(ndc_low, -1.0, 1.0) * 0.5 + 0.5) * u_resolution;
        vec2 pixel_high = (clamp(ndc_high, -1.0, 1.0) * 0.5 + 0.5) * u_resolution;
        low = clamp(ivec2(floor(pixel_low)) / u_list_tile, ivec2(0), u_list_grid.xy - 1);
        high = clamp(ivec2(floor(pixel_high)) / u_list_tile, ivec2(0), u_list_grid.xy - 1);
    }
    int first_slice = light_list_slice(max(near_depth, u_near_far.x));
    int last_slice = light_list_slice(far_depth);
    for (int slice = first_slice; slice <= last_slice; ++slice)
        for (int y = low.y; y <= high.y; ++y)
            for (int x = low.x; x <= high.x; ++x)
                light_list_append((slice * u_list_grid.y + y) * u_list_grid.x + x, index);
}
