// Lighting phase (Revie 2.4.3): one light, read from the G-buffer alone, added to light accumulation.
#include "gbuffer/fetch.glsl"
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"

#ifdef HAS_SSAO
uniform sampler2D u_ssao;
#endif
uniform vec2 u_resolution;
uniform mat4 u_inverse_projection;

flat in int v_light_index;
layout(location = 0) out vec4 out_light;
#ifdef SPLIT_LIGHTING
// the diffuse part of the light (deferred.interfaces.shading: models that split their light)
layout(location = 1) out vec4 out_diffuse;
#endif

void main() {
    GBufferSample g = gbuffer_fetch(ivec2(gl_FragCoord.xy));
    if (g.surface_id <= 0.0) discard;
#ifdef HAS_SSAO
    g.surface.occlusion = texelFetch(u_ssao, ivec2(gl_FragCoord.xy), 0).r;
#endif
    vec3 P = view_position(gl_FragCoord.xy, g.linear_depth, u_resolution, u_inverse_projection);
    vec3 V = normalize(-P);
#ifdef LIGHT_FUNCTION
    // the pass's one type (deferred.lighting.volumes.LightTypePass): the switch of evaluate_light would run
    // every type's evaluation on llvmpipe, where an `if` skips nothing
    out_light = vec4(LIGHT_FUNCTION(fetch_light(v_light_index), g.surface, P, V), 0.0);
#else
    out_light = vec4(evaluate_light(fetch_light(v_light_index), g.surface, P, V), 0.0);
#endif
#ifdef SPLIT_LIGHTING
    out_diffuse = vec4(split_light_diffuse, 0.0);
#endif
}
