// Fins (Lengyel et al. 2001): at silhouette edges, a strip extruded from the edge along the fur
// direction to the strand tips, so grazing fur reads as strands instead of stacked shell rims.
// Input: an edge with its two opposite vertices (lines_adjacency: c1, a, b, c2; the faces are
// (a, b, c1) and (b, a, c2) in mesh winding), each vertex carrying the fur vertex outputs under
// vs_ names (FUR_FINS). An edge gets a fin where the surface is edge-on to the viewer: the
// fin fades in as |N.V| of the edge's normal (the mean of its faces') drops below u_fin_band,
// fully opaque at the silhouette, so fins never pop as the silhouette moves across the mesh.
// With FIN_STRAND_TANGENT the vertices' vs_strand_tangent passes through (strand shading).
layout(lines_adjacency) in;
layout(triangle_strip, max_vertices = 4) out;

in vec3 vs_position[];
in vec3 vs_normal[];
in vec3 vs_tangent[];
in vec3 vs_binormal[];
in vec2 vs_uv[];
in vec4 vs_comb[];
in vec4 vs_base_clip[];
in vec4 vs_tip_clip[];
in float vs_base_depth[];
in float vs_tip_depth[];
in float vs_fur_extent[];
in float vs_shell_depth[];
in vec3 vs_fur_position[];
in vec3 vs_fur_normal[];
in vec3 vs_tip_position[];
in vec3 vs_base_position[];
#ifdef FIN_STRAND_TANGENT
in vec3 vs_strand_tangent[];
out vec3 v_strand_tangent;
#endif

uniform float u_fin_band;  // |N.V| below which an edge grows a fin
#ifdef SHADOW_CASTER
// Drawn from a light (materials/techniques/fur_shadow.py): the fins at the fur's silhouette as
// the light sees it; into the depth map pushed a strand's length from the light, as the fur
// vertex shader pushes the shells (not into the deep opacity maps: OPACITY_CASTER)
uniform mat4 u_projection;
#endif

out vec3 v_position;
out vec3 v_normal;
out vec3 v_tangent;
out vec3 v_binormal;
out vec2 v_uv;
out vec4 v_comb;
out vec4 v_base_clip;
out vec4 v_tip_clip;
out float v_base_depth;
out float v_tip_depth;
out float v_fur_extent;
out float v_shell_depth;
out vec3 v_fur_position;
out vec3 v_fur_normal;
out vec3 v_tip_position;
out vec3 v_base_position;
out float v_fin_fade;

void emit(int i, bool tip, float fade) {
    v_position = tip ? vs_tip_position[i] : vs_position[i];
    v_normal = vs_normal[i];
    v_tangent = vs_tangent[i];
    v_binormal = vs_binormal[i];
    v_uv = vs_uv[i];
    v_comb = vs_comb[i];
    v_base_clip = vs_base_clip[i];
    v_tip_clip = vs_tip_clip[i];
    v_base_depth = vs_base_depth[i];
    v_tip_depth = vs_tip_depth[i];
    v_fur_extent = vs_fur_extent[i];
    v_shell_depth = tip ? 1.0 : 0.0;
    v_fur_position = vs_fur_position[i];
    v_fur_normal = vs_fur_normal[i];
    v_tip_position = vs_tip_position[i];
    v_base_position = vs_base_position[i];
    v_fin_fade = fade;
#ifdef FIN_STRAND_TANGENT
    v_strand_tangent = vs_strand_tangent[i];
#endif
#if defined(SHADOW_CASTER) && !defined(OPACITY_CASTER)
    vec3 p = tip ? vs_tip_position[i] : vs_position[i];
    gl_Position = u_projection * vec4(p.xy, p.z - vs_fur_extent[i], 1.0);
#else
    gl_Position = tip ? vs_tip_clip[i] : vs_base_clip[i];
#endif
    EmitVertex();
}

vec3 safe_normalize(vec3 v) {
    float length_squared = dot(v, v);
    return length_squared > 1e-20 ? v * inversesqrt(length_squared) : vec3(0.0);
}

void main() {
    vec3 a = vs_position[1];
    vec3 b = vs_position[2];
    vec3 n1 = safe_normalize(cross(b - a, vs_position[0] - a));
    vec3 n2 = safe_normalize(cross(a - b, vs_position[3] - b));
    vec3 V = safe_normalize(-0.5 * (a + b));
#ifdef SHADOW_CASTER
    if (u_projection[3][3] == 1.0) V = vec3(0.0, 0.0, 1.0);  // a directional light's orthographic view
#endif
    vec3 edge_normal = n1 + n2;
    if (dot(edge_normal, edge_normal) < 1e-8) return;  // a knife edge or a degenerate face
    float fade = 1.0 - smoothstep(0.0, u_fin_band, abs(dot(normalize(edge_normal), V)));
    // A fin seen along its edge is a line: fade it as its plane turns edge-on to the eye.
    vec3 fin_normal = safe_normalize(cross(b - a, vs_tip_position[1] - a));
    fade *= smoothstep(0.1, 0.4, abs(dot(fin_normal, V)));
    if (fade <= 0.0) return;
    emit(1, false, fade);
    emit(2, false, fade);
    emit(1, true, fade);
    emit(2, true, fade);
    EndPrimitive();
}
