// One layer of glass at a fragment, what every mode composes (materials/glass/__init__.py):
// - emitted: the light it sends toward the viewer (its scattered part and its highlight, lit
//   by every light of the frame and their shadows);
// - coverage: per channel, the fraction of what lies behind it that it keeps from the viewer:
//   1 - (1 - opacity) (1 - F) colour, F Schlick's Fresnel reflectance of glass (F0 = 0.04) at
//   the view angle, so a grazing pane hides more of what is behind it;
// - offset: where what is seen through it is read, moved on the screen against the slant of
//   the mesh's outward normal (refraction as a screen-space offset), in units of the frame's
//   height: each face of a closed mesh bends it the same way, as a solid lens does;
// - depth: its linear view depth.
#include "common/surface_input.glsl"
#include "common/forward_lighting.glsl"
#include SURFACE_FILE

uniform float u_refraction;  // offset per unit of the normal's slant, a fraction of the height

const float GLASS_F0 = 0.04;

struct GlassLayer {
    vec3 emitted;
    vec3 coverage;
    vec2 offset;
    float depth;
};

GlassLayer glass_layer() {
    SurfaceInput i = surface_input();
    Surface s = evaluate_surface(i);
    vec3 V = normalize(-i.position);
    float cos_view = clamp(dot(s.normal, V), 0.0, 1.0);
    float fresnel = GLASS_F0 + (1.0 - GLASS_F0) * pow(1.0 - cos_view, 5.0);
    GlassLayer g;
    g.emitted = forward_lighting(s, i.position, V);
    g.coverage = 1.0 - (1.0 - u_glass_opacity) * (1.0 - fresnel) * u_color;
    g.offset = -i.normal.xy * u_refraction;
    g.depth = -i.position.z;
    return g;
}
