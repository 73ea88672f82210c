// A shadow caster's depth from a light (deferred.lighting.shadows): the mesh's world position
// through the light's view and projection; the viewport is the map's tile of the atlas.
in vec3 in_position;

uniform mat4 u_model;
uniform mat4 u_shadow_view_projection;  // world -> the light's clip space

void main() {
    gl_Position = u_shadow_view_projection * (u_model * vec4(in_position, 1.0));
}
