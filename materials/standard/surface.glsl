// Standard material: Blinn-Phong surface with a colour, an optional albedo texture and the
// G-buffer's specular intensity and exponent (Revie Figure 2.2).
#include "common/surface.glsl"

uniform vec3 u_color;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
#ifdef HAS_ALBEDO_TEXTURE
uniform sampler2D u_albedo_texture;
#endif

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
#ifdef HAS_ALBEDO_TEXTURE
    s.albedo *= texture(u_albedo_texture, i.uv).rgb;
#endif
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = i.normal;
    return s;
}
