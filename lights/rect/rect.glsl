// Rectangular area light (lights/rect): its record is a sphere light's (centre and range in
// position, unit normal in direction, radiance in color) and its data the rectangle's half axes
// (view space). Lit through the shading models' area answers (lighting/area_light.glsl);
// shadowed through six cube tiles around its centre, filtered by its size (PCSS).
#include "lighting/area_light.glsl"

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
    return shade_area_light(light, s, P, V, area, centre);
}
