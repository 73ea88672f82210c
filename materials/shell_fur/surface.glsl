// shell_fur's base surface (the G-buffer and the forward base pass): the colour texture, the
// Kajiya-Kay specular, and the strand's chord as the G-buffer's strand_tangent (fur.vert with
// STRAND_CHORD), which the lights shade and the deferred layers take their light from. What
// shows of it is the skin drawn over it.
#include "common/surface.glsl"
#include "materials/techniques/strand_tangent.glsl"
#include "materials/shell_fur/color.glsl"
#include "materials/shell_fur/wet.glsl"

uniform float u_specular_intensity;  // K_s
uniform float u_specular_exponent;   // p_phong
#ifdef FUR_MARSCHNER
uniform float u_roughness;           // the marschner shading model's beta, radians
#endif

in vec3 v_strand_tangent;

Surface material_surface(SurfaceInput i) {
    Surface s;
    float wetness = fur_wetness(i.uv);
    s.albedo = wet_albedo(fur_color(i.uv), wetness);
    s.specular_intensity = wet_specular_intensity(u_specular_intensity, wetness);
#ifdef FUR_MARSCHNER
    s.specular_exponent = wet_specular_shape(u_roughness, wetness);  // marschner's roughness
#else
    s.specular_exponent = wet_specular_shape(u_specular_exponent, wetness);
#endif
    s.normal = i.normal;
    s.data.strand_tangent = strand_tangent_encode(v_strand_tangent);
    return s;
}
