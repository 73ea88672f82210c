// Velvet surface: albedo, the sheen in the Blinn-Phong slots of the core G-buffer (intensity,
// exponent) and the sheen colour and wrap in the velvet model's own channel.
#include "common/surface.glsl"

uniform vec3 u_color;
uniform vec3 u_sheen_color;
uniform float u_sheen;
uniform float u_sheen_falloff;
uniform float u_wrap;

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
    s.specular_intensity = u_sheen;
    s.specular_exponent = u_sheen_falloff;
    s.normal = i.normal;
    s.data.sheen = vec4(u_sheen_color, u_wrap);
    return s;
}
