// The environment light's map behind the scene (scene background = "environment"): each pixel
// shows the map in the direction of its view ray (deferred.render.pipeline), alpha 0 as the
// background colour has.
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"

in vec2 v_uv;
uniform mat4 u_inverse_projection;
out vec4 out_color;

void main() {
    vec4 ray = u_inverse_projection * vec4(v_uv * 2.0 - 1.0, 1.0, 1.0);
#ifdef LIGHT_RANGE_environment
    LightRecord light = fullscreen_light(LIGHT_RANGE_environment.x);
    out_color = vec4(environment_background(light, ray.xyz / ray.w), 0.0);
#else
    out_color = vec4(0.0);
#endif
}
