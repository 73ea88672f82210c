// shell_fur: the mesh as the fur layer at normalized length h = u_shell_depth (0 the skin),
// displaced by Silva et al.'s v_offset(h) = beta(h) + phi(h) (Eq. 1; strand.glsl): the Bezier
// of the vertex's simulated strand and the curl, which the wetness at the vertex undoes.
// u_strand_tips holds three texels per vertex (at 3 x its index): the tip deflection p - p_0
// (its triangles', averaged) and the curl's u and v (one frame for all copies of a vertex split
// at a UV seam).
// v_strand_tangent is the strand's direction there (d v_offset / dh), or with STRAND_CHORD the
// strand's chord, root to simulated tip (the base surface, the skin and the fins: one direction
// for the whole strand, the curl averaged out); the layers have the chord too (v_strand_chord).
// With FUR_FINS the outputs feed the fin geometry
// shader (materials/techniques/fins.geom) under vs_ names.
#include "materials/shell_fur/strand.glsl"

in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;
in vec3 in_tangent;
in vec3 in_binormal;
in vec4 in_comb;

#include "common/object_transform.glsl"
uniform mat4 u_projection;
uniform float u_shell_depth;    // h
uniform float u_fur_length;     // object units, scaled per vertex by the vertex colour alpha
uniform vec3 u_fur_scale;       // object axes to world units (the model matrix's scale)
uniform float u_curl_radius;    // K, object units
uniform float u_curl_frequency; // w, radians over the strand
uniform sampler2D u_wetness_mask;
uniform sampler2D u_strand_tips;  // RGBA32F: per vertex p - p_0, curl u, curl v; object space

#ifdef FUR_FINS
#define v_position vs_position
#define v_normal vs_normal
#define v_tangent vs_tangent
#define v_binormal vs_binormal
#define v_uv vs_uv
#define v_comb vs_comb
#define v_base_clip vs_base_clip
#define v_tip_clip vs_tip_clip
#define v_base_depth vs_base_depth
#define v_tip_depth vs_tip_depth
#define v_fur_extent vs_fur_extent
#define v_shell_depth vs_shell_depth
#define v_fur_position vs_fur_position
#define v_fur_normal vs_fur_normal
#define v_tip_position vs_tip_position
#define v_base_position vs_base_position
#define v_strand_tangent vs_strand_tangent
#endif

out vec3 v_position;
out vec3 v_normal;
out vec3 v_tangent;
out vec3 v_binormal;
out vec2 v_uv;
out vec4 v_comb;
out vec4 v_base_clip;     // the root under this layer point (its light sample)
out vec4 v_tip_clip;      // the strand's tip (fins)
out float v_base_depth;   // linear view depths of those two points
out float v_tip_depth;
out float v_fur_extent;   // view-space length of the strand at this vertex
out float v_shell_depth;
out vec3 v_fur_position;  // the root in world-scaled object space (fur volume lookups)
out vec3 v_fur_normal;    // object-space normal (triplanar weights)
out vec3 v_tip_position;  // view space (fins)
out vec3 v_base_position; // view space: the root (the deferred layers relight from it)
out vec3 v_strand_tangent;  // view space
#if !defined(STRAND_CHORD) && !defined(FUR_FINS)
out vec3 v_strand_chord;    // view space: the chord, as the base surface was lit (shell.frag)
#endif

invariant gl_Position;

vec3 strand_texel(int k) {
    int index = 3 * gl_VertexID + k;
    int width = textureSize(u_strand_tips, 0).x;
    return texelFetch(u_strand_tips, ivec2(index % width, index / width), 0).xyz;
}

vec3 strand_offset(float h, vec3 rest_tip, vec3 tip, float wetness, vec3 u, vec3 v) {
    return strand_bend(in_position, rest_tip, tip, h)
         + curl_offset(h, wetness, u_curl_radius, u_curl_frequency, u, v);
}

void main() {
    mat4 model_view = object_model_view();
    mat3 normal_matrix = object_normal_matrix();
    float fur_length = u_fur_length * in_comb.a;
    vec3 rest_tip = in_position + in_normal * fur_length;  // p_0
    vec3 tip = constrain_tip(in_position, in_normal, fur_length, rest_tip + strand_texel(0));
    vec3 curl_u = strand_texel(1);
    vec3 curl_v = strand_texel(2);
    float wetness = textureLod(u_wetness_mask, in_uv, 0.0).a;

    float h = u_shell_depth;
    vec3 layer = in_position + strand_offset(h, rest_tip, tip, wetness, curl_u, curl_v);
    vec3 tip_point = in_position + strand_offset(1.0, rest_tip, tip, wetness, curl_u, curl_v);
#ifdef STRAND_CHORD
    vec3 direction = tip - in_position;
#else
    vec3 direction = strand_bend_derivative(in_position, rest_tip, tip, h)
        + curl_derivative(h, wetness, u_curl_radius, u_curl_frequency, curl_u, curl_v);
#endif
    direction = dot(direction, direction) > 1e-20 ? direction : in_normal;

    vec4 position = model_view * vec4(layer, 1.0);
    vec4 base_view = model_view * vec4(in_position, 1.0);
    vec4 tip_view = model_view * vec4(tip_point, 1.0);
    v_position = position.xyz;
    v_normal = normalize(normal_matrix * in_normal);
    v_tangent = normalize(mat3(model_view) * in_tangent);
    v_binormal = normalize(mat3(model_view) * in_binormal);
    v_uv = in_uv;
    v_comb = in_comb;
    v_base_clip = u_projection * base_view;
    v_tip_clip = u_projection * tip_view;
    v_base_depth = -base_view.z;
    v_tip_depth = -tip_view.z;
    v_fur_extent = length(tip_view.xyz - base_view.xyz);
    v_shell_depth = h;
    v_fur_position = in_position * u_fur_scale;
    v_fur_normal = in_normal;
    v_tip_position = tip_view.xyz;
    v_base_position = base_view.xyz;
    v_strand_tangent = normalize(mat3(model_view) * direction);
#if !defined(STRAND_CHORD) && !defined(FUR_FINS)
    vec3 chord = tip - in_position;
    v_strand_chord = normalize(mat3(model_view) * (dot(chord, chord) > 1e-20 ? chord : in_normal));
#endif
#if defined(SHADOW_CASTER) && !defined(OPACITY_CASTER)
    // drawn from the light (deferred.api.SHADOW_CASTER_DEFINES): the fur casts a strand's
    // length further from the light, onto other surfaces but not onto its own skin and
    // shells, whose self-shadowing is the deep opacity maps' (OPACITY_CASTER: drawn where it
    // is; deferred.lighting.shadows) or gamma(h) (materials/techniques/fur.glsl)
    position.z -= v_fur_extent;
#endif
    gl_Position = u_projection * position;
}
