// Revie fur, forward technique (2.4: "a separate technique ... in a forward-shaded fashion"):
// each shell fragment is lit directly by every light, with the grain normal and, as the
// deferred stipple sample does, with the rim-bent normal; the brighter wins. Albedo and strand
// fading are those of the deferred shells.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include "techniques/rim.glsl"
#include SURFACE_FILE

uniform sampler2D u_heightfield;
uniform vec3 u_albedo_base;
uniform float u_density;
uniform float u_strand_softness;
uniform float u_rim_strength;
uniform float u_rim_falloff;

in float v_shell_depth;
out vec4 out_color;

void main() {
    SurfaceInput i = surface_input();
    float height = texture(u_heightfield, i.uv * u_density).r;
    float alpha = 1.0 - smoothstep(height - u_strand_softness, height, v_shell_depth);
    if (alpha <= 0.0) discard;
    Surface s = evaluate_surface(i);
    vec3 V = normalize(-i.position);
    vec3 light = forward_lighting(s, i.position, V);
#ifdef FUR_STIPPLE
    Surface rim = s;
    rim.normal = rim_bend(i.normal, s.normal, -V, u_rim_strength, u_rim_falloff);
    light = max(light, forward_lighting(rim, i.position, V));
#endif
    vec3 irradiance = light / max(s.albedo, vec3(1.0 / 255.0));
    out_color = vec4(irradiance * mix(u_albedo_base, s.albedo, v_shell_depth), alpha);
}
