// Revie fur surface for the G-buffer and the forward base pass: the outer albedo, specular, and
// the anisotropic grain normal (Listing 2.5) unless `anisotropic` is off. What shows of the base
// is the root shell drawn over it (the skin); this albedo is what the light samples divide out.
#include "common/surface.glsl"
#include "techniques/grain_normal.glsl"

uniform vec3 u_albedo_tip;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
uniform bool u_anisotropic;

vec3 fur_comb_view(SurfaceInput i) {
    vec3 c = i.comb.xyz * 2.0 - 1.0;
    return i.tangent * c.x + i.binormal * c.y + i.normal * c.z;
}

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_albedo_tip;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = u_anisotropic ? grain_normal(i.normal, fur_comb_view(i), normalize(i.position))
                             : i.normal;
    return s;
}
