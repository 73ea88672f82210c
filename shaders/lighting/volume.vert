// A light's bounding sphere (instanced, one instance per light of the type).
#include "common/light_buffer.glsl"

in vec3 in_position;

uniform mat4 u_projection;
uniform int u_light_offset;
uniform float u_volume_scale;  // makes the icosphere enclose the unit sphere

flat out int v_light_index;

void main() {
    v_light_index = u_light_offset + gl_InstanceID;
    LightRecord light = fetch_light(v_light_index);
    vec3 position = light.position.xyz + in_position * light.position.w * u_volume_scale;
    gl_Position = u_projection * vec4(position, 1.0);
}
