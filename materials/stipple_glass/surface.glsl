// Stipple glass: a tinted, shiny surface (its G-buffer sample is lit like any other).
#include "common/surface.glsl"

uniform vec3 u_color;
uniform float u_specular_intensity;
uniform float u_specular_exponent;

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = i.normal;
    return s;
}
