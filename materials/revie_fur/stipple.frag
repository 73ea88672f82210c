// Revie geometry pass 2 (2.4.2, Figure 2.17): the outermost shell into one pixel of every 2x2
// tile, with rim-bent normals at silhouettes (Listing 2.3) over the grain normals.
#include "common/surface_input.glsl"
#include "gbuffer/write.glsl"
#include "materials/techniques/stipple.glsl"
#include "materials/techniques/rim.glsl"
#include SURFACE_FILE

uniform float u_rim_strength;
uniform float u_rim_falloff;

void main() {
    if (!stipple_sample(ivec2(gl_FragCoord.xy))) discard;
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
#ifndef FUR_MARSCHNER  // the hair model's TT lobe lights the back-lit rim instead
    s.normal = rim_bend(i.normal, s.normal, normalize(i.position), u_rim_strength, u_rim_falloff);
#endif
    gbuffer_write(s, i.position, u_surface_id);
}
