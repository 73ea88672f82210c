// What every area light type (lights/rect, lights/disc) does once it has its polygon: the light
// through thin parts, the shadow of its cube tiles (PCSS, filtered by its size) and the shading
// models' area answer (shade_area).
#include "common/lighting.glsl"
#include "lighting/area.glsl"
#include "lighting/shadows.glsl"

// ``area``: the light's polygon (corners relative to P) and unshadowed radiance; ``centre``:
// the light's centre relative to P.
vec3 shade_area_light(LightRecord light, Surface s, vec3 P, vec3 V, AreaLight area,
                      vec3 centre) {
#ifdef SURFACE_TRANSMISSION
    vec3 J = area_vector_irradiance(area);  // the light as one direction, for the light through
    vec3 through = shade_transmission(s, normalize(J), V, area.radiance * length(J),
                                      light_thickness_cube(light, P, s.normal));
#endif
    area.radiance *= light_shadow_cube(light, P, s.normal, normalize(centre));
#ifdef SURFACE_TRANSMISSION
    return shade_area(s, V, area) + through;
#else
    return shade_area(s, V, area);
#endif
}
