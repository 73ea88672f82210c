// The subsurface model's answer to an area light: its diffuse part as Blinn-Phong's (the
// polygon's irradiance), counted as diffuse for the blur, and Blinn-Phong's area highlight.
#include "materials/shading_models/subsurface.glsl"
#include "materials/shading_models/blinn_phong_area.glsl"

vec3 subsurface_area(Surface s, vec3 V, AreaLight a) {
    vec3 diffuse = a.radiance * s.albedo * area_irradiance(a, s.normal);
#ifdef SPLIT_LIGHTING  // always, where a scene has the model
    split_light_diffuse += diffuse;
#endif
    return diffuse + a.radiance * blinn_phong_area_specular(s, V, a);
}
