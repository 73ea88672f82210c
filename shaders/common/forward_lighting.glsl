// Forward shading: the lights of the frame evaluated at one surface point, each through the
// surface's shading model (the same GLSL the deferred lights call). Naive forward loops over
// every light (a loop per light type, generated/lights.glsl); Forward+ (FORWARD_PLUS) over the
// full-screen lights and the volume lights of the pixel's tile, and so does the deferred
// pipeline's tiled or clustered path for the transparent surfaces it lights after the opaque
// scene (LISTED_LIGHTS: their lists are culled from the near plane, or by clusters).
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
// SCREEN_OCCLUSION: the ambient occlusion a screen effect found at this pixel for the opaque
// surface drawn there (deferred.interfaces.techniques.ForwardLitPass.read_occlusion)
#ifdef SCREEN_OCCLUSION
uniform sampler2D u_ssao;
#define SCREEN_OCCLUSION_AT(s) s.occlusion = texelFetch(u_ssao, ivec2(gl_FragCoord.xy), 0).r
#else
#define SCREEN_OCCLUSION_AT(s)
#endif
#if defined(FORWARD_PLUS) || defined(LISTED_LIGHTS)
#include "lighting/listed_lights.glsl"

vec3 forward_lighting(Surface s, vec3 P, vec3 V) {
    s.view_depth = -P.z;
    SCREEN_OCCLUSION_AT(s);
    int list = light_list_of(ivec2(gl_FragCoord.xy), -P.z);
    return evaluate_fullscreen_lights(s, P, V) + evaluate_listed_lights(list, s, P, V);
}
#else
vec3 forward_lighting(Surface s, vec3 P, vec3 V) {
    s.view_depth = -P.z;
    SCREEN_OCCLUSION_AT(s);
    return evaluate_fullscreen_lights(s, P, V) + evaluate_volume_lights(s, P, V);
}
#endif
