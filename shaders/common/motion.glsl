// Motion vectors (deferred.effects.taa): an object-space point's clip position this frame and
// the last, both without the frame's sub-pixel jitter. The framework sets the uniforms for every
// program that declares them: u_previous_model per object (the model of the last frame rendered;
// the model itself on a first frame or after a cut), u_view_projection and
// u_previous_view_projection from the camera (unjittered).
uniform mat4 u_previous_model;
uniform mat4 u_view_projection;
uniform mat4 u_previous_view_projection;

vec4 motion_clip_current(mat4 model, vec3 object_position) {
    return u_view_projection * (model * vec4(object_position, 1.0));
}

vec4 motion_clip_previous(vec3 object_position) {
    return u_previous_view_projection * (u_previous_model * vec4(object_position, 1.0));
}

// Motion in pixels between two clip positions (this frame's minus the last's).
vec2 motion_pixels(vec4 current_clip, vec4 previous_clip, vec2 resolution) {
    vec2 current = current_clip.xy / current_clip.w;
    vec2 previous = previous_clip.xy / previous_clip.w;
    return (current - previous) * 0.5 * resolution;
}
