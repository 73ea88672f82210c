// The subsurface material's surface: its albedo, Blinn-Phong highlight and its row of the
// scene's profile table (the datum subsurface_profile).
#include "common/surface.glsl"
uniform vec3 u_color;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
uniform float u_subsurface_row;

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = i.normal;
    s.data.subsurface_profile = vec4(u_subsurface_row / 255.0);
    return s;
}
