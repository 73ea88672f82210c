// Rectangular area light (lights/rect): its record is a sphere light's (centre and range in
// position, unit normal in direction, radiance in color) and its data the rectangle's half axes
// (view space). Lit through the shading models' area answers (shade_area, lighting/area.glsl);
// shadowed through six cube tiles around its centre, filtered by its size (PCSS).
#include "common/lighting.glsl"
#include "lighting/area.glsl"
#include "lighting/shadows.glsl"

vec3 rect_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    rect_light_Data data = rect_light_data(light);
    vec3 centre = light.position.xyz - P;
    float window = area_light_window(light, centre);
    if (window <= 0.0) return vec3(0.0);
    AreaLight area;
    area.count = 4;
    vec3 x = data.axis_x.xyz, y = data.axis_y.xyz;
    area.corners[0] = centre - x - y;
    area.corners[1] = centre + x - y;
    area.corners[2] = centre + x + y;
    area.corners[3] = centre - x + y;
    area.radiance = light.color.rgb * window;
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
