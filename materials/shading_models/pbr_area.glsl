// pbr's answer to an area light (lighting/area.glsl): Lambert diffuse from the clipped
// polygon's irradiance, the GGX lobe by Heitz et al.'s LTC fit with Schlick's Fresnel split by
// its tables, times the model's multiple-scattering compensation (as pbr.glsl's point answer).
#include "materials/shading_models/pbr.glsl"
#include "lighting/area.glsl"

vec3 pbr_area(Surface s, vec3 V, AreaLight a) {
    PbrTerms t = pbr_terms(s, V);
    vec3 diffuse = t.diffuse / PBR_PI * area_irradiance(a, s.normal);
    vec3 lobe = area_ggx(a, s.normal, V, max(t.roughness, PBR_MIN_ROUGHNESS));
    vec3 specular = lobe.x * (t.f0 * lobe.y + (1.0 - t.f0) * lobe.z) * t.energy;
    return a.radiance * (diffuse + specular);
}
