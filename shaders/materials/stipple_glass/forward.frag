// Stipple glass, forward technique: lit by every light and alpha-blended by opacity, which is
// what the deferred deinterlace computes from the stipple samples.
#include "common/surface_input.glsl"
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include SURFACE_FILE

uniform float u_opacity;
out vec4 out_color;

void main() {
    SurfaceInput i = surface_input();
    Surface s = material_surface(i);
    s.occlusion = 1.0;
    vec3 V = normalize(-i.position);
    vec3 color = vec3(0.0);
    for (int k = 0; k < u_light_count; ++k) {
        color += evaluate_light(fetch_light(k), s, i.position, V);
    }
    out_color = vec4(color, u_opacity);
}
