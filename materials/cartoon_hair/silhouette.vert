// Silhouette strokes of hair tubes (Costigan 4.3.7): a tube vertex in view space for
// silhouette.geom, with its strand (comb.x) and its parameter along the strand (comb.y).
in vec3 in_position;
in vec3 in_normal;
in vec4 in_comb;

#include "common/object_transform.glsl"

out vec3 vs_position;
out vec3 vs_normal;
out float vs_along;
out float vs_strand;

void main() {
    vec4 position = object_model_view() * vec4(in_position, 1.0);
    vs_position = position.xyz;
    vs_normal = object_normal_matrix() * in_normal;
    vs_along = in_comb.y;
    vs_strand = in_comb.x;
    gl_Position = position;  // silhouette.geom projects
}
