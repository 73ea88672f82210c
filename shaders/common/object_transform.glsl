// An object's transform (deferred.render.caches.ObjectTransforms): its model matrix and the inverse
// transpose of the model's 3x3 (normals), and the camera's view, kept apart. A camera that
// moves changes one uniform a frame, not every object's: the view is a rigid motion (a
// look-at), so the normal matrix of view x model is mat3(view) x the model's.
uniform mat4 u_view;
uniform mat4 u_model;
uniform mat3 u_model_normal_matrix;

mat4 object_model_view() {
    return u_view * u_model;
}

mat3 object_normal_matrix() {
    return mat3(u_view) * u_model_normal_matrix;
}
