// The film's surface: no diffuse light of its own, a highlight; double-sided.
#include "common/surface.glsl"

uniform float u_specular_intensity;
uniform float u_specular_exponent;

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = vec3(0.0);
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = gl_FrontFacing ? i.normal : -i.normal;
    return s;
}
