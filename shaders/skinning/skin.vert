// Linear blend skinning (deferred.render.skinning): each vertex of a skinned mesh's rest
// surface moved by the weighted sum of its four joints' matrices, captured by transform
// feedback into the mesh's surface buffer, which every pass then draws.
in vec3 in_position;
in vec3 in_normal;
in vec3 in_tangent;
in vec3 in_binormal;
in vec4 in_joints;
in vec4 in_weights;

// a joint's matrix a row of four texels, its columns (object space: deferred.scene.skin)
uniform sampler2D u_joint_matrices;

out vec3 out_position;
out vec3 out_normal;
out vec3 out_tangent;
out vec3 out_binormal;

mat4 joint_matrix(float joint) {
    int row = int(joint + 0.5);
    return mat4(texelFetch(u_joint_matrices, ivec2(0, row), 0),
                texelFetch(u_joint_matrices, ivec2(1, row), 0),
                texelFetch(u_joint_matrices, ivec2(2, row), 0),
                texelFetch(u_joint_matrices, ivec2(3, row), 0));
}

void main() {
    mat4 skin = in_weights.x * joint_matrix(in_joints.x) + in_weights.y * joint_matrix(in_joints.y)
              + in_weights.z * joint_matrix(in_joints.z) + in_weights.w * joint_matrix(in_joints.w);
    mat3 linear = mat3(skin);
    // normals by the cofactor matrix (the inverse transpose up to a positive scale)
    mat3 cofactor = mat3(cross(linear[1], linear[2]), cross(linear[2], linear[0]),
                         cross(linear[0], linear[1]));
    float handed = determinant(linear) < 0.0 ? -1.0 : 1.0;
    out_position = (skin * vec4(in_position, 1.0)).xyz;
    out_normal = normalize(handed * (cofactor * in_normal));
    out_tangent = normalize(linear * in_tangent);
    out_binormal = normalize(linear * in_binormal);
}
