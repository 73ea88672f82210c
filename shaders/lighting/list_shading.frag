// Deferred lighting from light lists (the tiled and clustered paths): each pixel reads the
// G-buffer once and loops over the full-screen lights and the volume lights of its tile or
// cluster - one pass for every light. It runs on surface pixels only (its triangle on the far
// plane, the depth test "greater": deferred.lighting.volumes.surface_pass); its targets are
// cleared to the background first, so it writes the light accumulation whole.
#include "gbuffer/fetch.glsl"
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include "lighting/listed_lights.glsl"

#ifdef HAS_SSAO
uniform sampler2D u_ssao;
#endif
uniform vec2 u_resolution;
uniform mat4 u_inverse_projection;
uniform vec3 u_background;  // where the G-buffer holds no surface (alpha 0: coverage)

layout(location = 0) out vec4 out_light;
#ifdef WRITE_COMPOSITE
// the composition buffer, which the material phase starts from (deferred.lighting.culling)
layout(location = 1) out vec4 out_composite;
#endif
#ifdef SPLIT_LIGHTING
// the diffuse part of the light (deferred.interfaces.shading: models that split their light)
layout(location = 1) out vec4 out_diffuse;
#endif
#ifdef WRITE_SNAPSHOT
// a snapshot of the composition the material phase takes before its first write to it
layout(location = 2) out vec4 out_snapshot;
#endif

void write_light(vec4 light) {
    out_light = light;
#ifdef WRITE_COMPOSITE
    out_composite = light;
#endif
#ifdef SPLIT_LIGHTING
    out_diffuse = vec4(split_light_diffuse, light.a);
#endif
#ifdef WRITE_SNAPSHOT
    out_snapshot = light;
#endif
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    GBufferSample g = gbuffer_fetch(pixel);
    if (g.surface_id <= 0.0) {  // depth written but no surface: the background here too
        write_light(vec4(u_background, 0.0));
        return;
    }
#ifdef HAS_SSAO
    g.surface.occlusion = texelFetch(u_ssao, pixel, 0).r;
#endif
    vec3 P = view_position(gl_FragCoord.xy, g.linear_depth, u_resolution, u_inverse_projection);
    vec3 V = normalize(-P);
    vec3 total = evaluate_fullscreen_lights(g.surface, P, V);
#ifdef ALL_LIGHTS
    // brute force (benchmarks/brute_force.py): every volume light at every pixel, no lists
    total += evaluate_volume_lights(g.surface, P, V);
#else
    total += evaluate_listed_lights(light_list_of(pixel, g.linear_depth), g.surface, P, V);
#endif
    write_light(vec4(total, 1.0));
}
