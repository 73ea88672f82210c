// Forward shading: the lights of the frame evaluated at one surface point, each through the
// surface's shading model (the same GLSL the deferred lights call). Naive forward loops over
// every light (a loop per light type, generated/lights.glsl); Forward+ (FORWARD_PLUS) over the
// full-screen lights and the volume lights of the pixel's tile.
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#ifdef FORWARD_PLUS
#include "lights/light_lists.glsl"

vec3 forward_lighting(Surface s, vec3 P, vec3 V) {
    vec3 color = evaluate_fullscreen_lights(s, P, V);
    int list = light_list_of(ivec2(gl_FragCoord.xy), -P.z);
    int length = light_list_length(list);
    for (int k = 0; k < length; ++k) {
        int index = light_list_light(list, k);
        if (light_reaches(index, P)) color += evaluate_volume_light(fetch_light(index), s, P, V);
    }
    return color;
}
#else
vec3 forward_lighting(Surface s, vec3 P, vec3 V) {
    return evaluate_fullscreen_lights(s, P, V) + evaluate_volume_lights(s, P, V);
}
#endif
