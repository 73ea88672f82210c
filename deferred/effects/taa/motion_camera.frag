// Motion vectors of what only the camera moves (deferred.effects.taa): each pixel's point,
// from the depth, as the last frame's camera saw it. The background (depth 1) is a direction
// (w = 0): it moves with the camera's turn only, as the sky does.
#include "common/motion.glsl"

uniform sampler2D u_depth;
uniform mat4 u_inverse_projection;  // this frame's, jittered as the depth was drawn
uniform mat4 u_camera_to_world;     // the inverse of the view
uniform vec2 u_resolution;

out vec2 out_motion;

void main() {
    vec2 ndc = gl_FragCoord.xy / u_resolution * 2.0 - 1.0;
    float depth = texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r;
    vec4 world;
    if (depth >= 1.0) {
        vec4 ray = u_inverse_projection * vec4(ndc, 1.0, 1.0);
        world = u_camera_to_world * vec4(ray.xyz / ray.w, 0.0);
    } else {
        vec4 view = u_inverse_projection * vec4(ndc, depth * 2.0 - 1.0, 1.0);
        world = u_camera_to_world * vec4(view.xyz / view.w, 1.0);
    }
    out_motion = motion_pixels(u_view_projection * world, u_previous_view_projection * world,
                               u_resolution);
}
