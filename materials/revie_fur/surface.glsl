// Revie fur surface for the G-buffer and the forward base pass: the outer albedo, specular, and
// the anisotropic grain normal (Listing 2.5) unless `anisotropic` is off; with FUR_MARSCHNER
// (shading = "marschner") the strand direction and roughness for the hair shading model instead. What shows of the base
// is the root shell drawn over it (the skin); this albedo is what the light samples divide out.
#include "common/surface.glsl"
#include "materials/techniques/grain_normal.glsl"

uniform vec3 u_albedo_tip;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
uniform bool u_anisotropic;
#ifdef FUR_MARSCHNER
#include "materials/techniques/strand_tangent.glsl"
uniform float u_roughness;
#include "materials/revie_fur/comb.glsl"
#endif

vec3 fur_comb_view(SurfaceInput i) {
    vec3 c = i.comb.xyz * 2.0 - 1.0;
    return i.tangent * c.x + i.binormal * c.y + i.normal * c.z;
}

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_albedo_tip;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    vec3 comb = fur_comb_view(i);
#ifdef FUR_MARSCHNER
    // the hair shading model about the strand, root to tip: the normal leaning along the comb
    // as the shells lean (fur.vert, materials/techniques/shells.glsl)
    s.normal = i.normal;
    s.specular_exponent = u_roughness;
    s.data.strand_tangent = strand_tangent_encode(normalize(i.normal + comb * u_comb_strength));
    return s;
#endif
    // the comb's length is the lean (comb_field.py): upright strands in a crown have no grain
    s.normal = u_anisotropic ? normalize(mix(i.normal,
                                             grain_normal(i.normal, comb, normalize(i.position)),
                                             clamp(length(comb), 0.0, 1.0)))
                             : i.normal;
    return s;
}
