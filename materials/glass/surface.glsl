// Glass: a thin transparent surface. What it scatters itself (its opacity) is lit as a
// Blinn-Phong surface whose albedo is its colour; its specular highlight is reflected on top.
// Seen from behind (glass is drawn double-sided) its normal faces the viewer.
#include "common/surface.glsl"

uniform vec3 u_color;
uniform float u_glass_opacity;
uniform float u_specular_intensity;
uniform float u_specular_exponent;

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color * u_glass_opacity;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = gl_FrontFacing ? i.normal : -i.normal;
    return s;
}
