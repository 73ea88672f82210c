// Silhouette strokes of hair tubes (Costigan 4.3.7, Fig. 4.17, 4.19): the stroke image in
// u_stroke_color, its alpha faded toward the roots by the quadratic u_stroke_fade of the
// parameter along the strand, clamped to [0, 1]. With STROKE_ID_BUFFER (deferred; Northrup's
// ID buffer) a fragment is drawn where the G-buffer holds the stroke's own strand, or where
// the stroke is at most u_stroke_tolerance behind the G-buffer's depth (or over background).
uniform sampler2D u_stroke;
uniform vec3 u_stroke_color;
uniform vec3 u_stroke_fade;
#ifdef STROKE_ID_BUFFER
uniform sampler2D u_strand_id;
uniform sampler2D u_linear_depth;
uniform float u_stroke_tolerance;
uniform float u_strand_base;  // the object's first strand id (cartoon_hair.strand_base)
#endif

in vec2 g_stroke_uv;
in float g_view_depth;
flat in float g_strand;

out vec4 out_color;

void main() {
#ifdef STROKE_ID_BUFFER
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float id = texelFetch(u_strand_id, pixel, 0).r;
    float scene_depth = texelFetch(u_linear_depth, pixel, 0).r;  // 0: background
    bool own = abs(id - (u_strand_base + g_strand + 1.0)) < 0.5;
    bool in_front = scene_depth <= 0.0 || g_view_depth - u_stroke_tolerance <= scene_depth;
    if (!own && !in_front) discard;
#endif
    float x = clamp(g_stroke_uv.x, 0.0, 1.0);
    float fade = clamp((u_stroke_fade.x * x + u_stroke_fade.y) * x + u_stroke_fade.z, 0.0, 1.0);
    float ink = texture(u_stroke, g_stroke_uv).r;
    float alpha = ink * fade;
    if (alpha <= 0.0) discard;
    out_color = vec4(u_stroke_color, alpha);
}
