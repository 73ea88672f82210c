// Wax surface: albedo and highlight in the core G-buffer, the wrap and the mean free path in
// the wax model's own channel.
#include "common/surface.glsl"

uniform vec3 u_color;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
uniform float u_wrap;
uniform float u_mean_free_path;

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = i.normal;
    s.data.wax = vec4(u_wrap, u_mean_free_path, 0.0, 0.0);
    return s;
}
