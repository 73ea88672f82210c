// Motion vectors of an object (deferred.effects.taa): its mesh pushed out along the normals by
// what its material draws beyond it (Material.motion_extent: fur shells and fins, hair), drawn
// where it is nearest, with this frame's and the last frame's model and camera (and a skinned
// mesh's surface of the last frame: deferred.render.skinning).
in vec3 in_position;
in vec3 in_normal;
#ifdef SKINNED_MOTION
in vec3 in_previous_position;  // a skinned mesh's surface in the frame before
#endif

#include "common/object_transform.glsl"
#include "common/motion.glsl"
uniform mat4 u_projection;
uniform float u_motion_extent;

out vec4 v_current;
out vec4 v_previous;

invariant gl_Position;

void main() {
    vec3 p = in_position + normalize(in_normal) * u_motion_extent;
    v_current = motion_clip_current(u_model, p);
#ifdef SKINNED_MOTION
    v_previous = motion_clip_previous(in_previous_position + normalize(in_normal) * u_motion_extent);
#else
    v_previous = motion_clip_previous(p);
#endif
    gl_Position = u_projection * (object_model_view() * vec4(p, 1.0));
}
