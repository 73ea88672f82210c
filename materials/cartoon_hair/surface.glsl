// Cartoon hair (Costigan 4.3.3): the head in its skin colour and the hair's tubes in the hair
// colour, both shaded by the toon model through the material's X-toon ramp (the G-buffer datum
// toon_ramp); the tubes write their strand into strand_id (1 + the object's first strand id +
// the strand's index; 0 on the head), so
// the edges effect outlines strands of one colour where they overlap. The tubes carry the
// strand's index in the comb slot (deferred.materials.cartoon_hair).
#include "common/surface.glsl"

uniform vec3 u_color;
uniform float u_specular_intensity;
uniform float u_specular_exponent;
uniform float u_ramp_row;
uniform bool u_hair;
uniform float u_strand_base;  // the object's first strand id (an id range a hair object)

Surface material_surface(SurfaceInput i) {
    Surface s;
    s.albedo = u_color;
    s.specular_intensity = u_specular_intensity;
    s.specular_exponent = u_specular_exponent;
    s.normal = i.normal;
    s.data.toon_ramp = vec4(u_ramp_row, 0.0, 0.0, 0.0);
    // every vertex of a tube holds its strand: interpolation only rounds it
    s.data.strand_id = vec4(u_hair ? u_strand_base + floor(i.comb.x + 0.5) + 1.0 : 0.0,
                            0.0, 0.0, 0.0);
    return s;
}
