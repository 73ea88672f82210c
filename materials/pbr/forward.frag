// The pbr material lit by every light in one pass: the forward pipeline's surfaces, and blended
// surfaces in both pipelines (alpha mode "blend": drawn after the opaque scene, far to near,
// with the opaque scene's lights and shadows). Its emission is added to the light.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include SURFACE_FILE

out vec4 out_color;

void main() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    vec3 light = forward_lighting(s, i.position, normalize(-i.position));
    out_color = vec4(light + pbr_emitted, pbr_alpha);
}
