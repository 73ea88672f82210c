// Forward pipeline: a material's surface lit by every light of the frame in one pass.
#include "common/surface_input.glsl"
#include "common/light_buffer.glsl"
#include "generated/lights.glsl"
#include SURFACE_FILE

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
    out_color = vec4(color, 1.0);
}
