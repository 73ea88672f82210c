// Disc (elliptical) area light (lights/disc): as the rect light, with the ellipse taken as the
// regular 12-gon of its area (the half axes in its data are that polygon's circumradii).
#include "lighting/area_light.glsl"

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
    return shade_area_light(light, s, P, V, area, centre);
}
