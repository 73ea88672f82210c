// Motion vectors of an object (deferred.effects.taa): its mesh pushed out along the normals by
// what its material draws beyond it (Material.motion_extent: fur shells and fins, hair), drawn
// where it is nearest, with this frame's and the last frame's model and camera (and a skinned
// mesh's surface of the last frame, deferred.render.skinning, or a simulated one's,
// Motion.surfaces: PREVIOUS_SURFACE).
in vec3 in_position;
in vec3 in_normal;
#ifdef PREVIOUS_SURFACE
in vec3 in_previous_position;  // a skinned or simulated mesh's surface in the frame before
#endif

#include "common/object_transform.glsl"
#include "common/motion.glsl"
uniform mat4 u_projection;
uniform float u_motion_extent;
#ifdef MOTION_OFFSETS
// where the reach moves on its own (Motion.offsets: a strand tip in the wind), object space,
// this frame's and the last frame's, vertex i's at texel stride * i
uniform sampler2D u_motion_offsets;
uniform sampler2D u_previous_motion_offsets;
uniform int u_motion_offset_stride;

vec3 motion_offset(sampler2D offsets) {
    int index = u_motion_offset_stride * gl_VertexID;
    int width = textureSize(offsets, 0).x;
    return texelFetch(offsets, ivec2(index % width, index / width), 0).xyz;
}
#endif

out vec4 v_current;
out vec4 v_previous;

invariant gl_Position;

void main() {
    vec3 p = in_position + normalize(in_normal) * u_motion_extent;
#ifdef PREVIOUS_SURFACE
    vec3 previous = in_previous_position + normalize(in_normal) * u_motion_extent;
#else
    vec3 previous = p;
#endif
#ifdef MOTION_OFFSETS
    p += motion_offset(u_motion_offsets);
    previous += motion_offset(u_previous_motion_offsets);
#endif
    v_current = motion_clip_current(u_model, p);
    v_previous = motion_clip_previous(previous);
    gl_Position = u_projection * (object_model_view() * vec4(p, 1.0));
}
