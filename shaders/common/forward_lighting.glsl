// Forward shading: every light of the frame evaluated at one surface point, each through the
// surface's shading model (the same GLSL the deferred lights call).
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"

vec3 forward_lighting(Surface s, vec3 P, vec3 V) {
    vec3 color = vec3(0.0);
    for (int k = 0; k < u_light_count; ++k) {
        color += evaluate_light(fetch_light(k), s, P, V);
    }
    return color;
}
