// Disc (elliptical) area light (lights/disc): as the rect light, with the ellipse taken as the
// regular 12-gon of its area (the half axes in its data are that polygon's circumradii).
#include "common/lighting.glsl"
#include "lighting/area.glsl"
#include "lighting/shadows.glsl"

vec3 disc_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    disc_light_Data data = disc_light_data(light);
    vec3 centre = light.position.xyz - P;
    float window = area_light_window(light, centre);
    if (window <= 0.0) return vec3(0.0);
    AreaLight area;
    area.count = 12;
    for (int k = 0; k < 12; ++k) {
        float angle = float(k) * (6.28318530718 / 12.0);
        area.corners[k] = centre + cos(angle) * data.axis_x.xyz + sin(angle) * data.axis_y.xyz;
    }
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
