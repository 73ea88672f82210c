// Vertex shader of every mesh pass: transforms the framework's vertex format to view space.
// With MESH_EXTRAS it reads the mesh's extra attributes too (deferred.gl.meshes: a second UV set,
// a vertex colour, and tangents with their handedness in place of the tangent and binormal).
in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;
in vec3 in_tangent;
in vec3 in_binormal;
in vec4 in_comb;
#ifdef MESH_EXTRAS
in vec2 in_uv1;
in vec4 in_color;
in vec4 in_tangent4;
out vec2 v_uv1;
out vec4 v_color;
#endif

#include "common/object_transform.glsl"
uniform mat4 u_projection;

out vec3 v_position;
out vec3 v_normal;
out vec3 v_tangent;
out vec3 v_binormal;
out vec2 v_uv;
out vec4 v_comb;

// Passes that draw the same mesh twice and compare depths need bit-identical positions.
invariant gl_Position;

void main() {
    mat4 model_view = object_model_view();
    mat3 normal_matrix = object_normal_matrix();
    vec4 position = model_view * vec4(in_position, 1.0);
    v_position = position.xyz;
    v_normal = normalize(normal_matrix * in_normal);
#ifdef MESH_EXTRAS
    // the bitangent as glTF defines it, cross(normal, tangent) * w, in view space
    v_tangent = normalize(mat3(model_view) * in_tangent4.xyz);
    v_binormal = cross(v_normal, v_tangent) * (in_tangent4.w < 0.0 ? -1.0 : 1.0);
    v_uv1 = in_uv1;
    v_color = in_color;
#else
    v_tangent = normalize(mat3(model_view) * in_tangent);
    v_binormal = normalize(mat3(model_view) * in_binormal);
#endif
    v_uv = in_uv;
    v_comb = in_comb;
    gl_Position = u_projection * position;
}
