// Revie fur: the mesh at a shell depth (0 base, 1 outermost shell), leaning along the comb field:
// one object-space comb per vertex (direction x lean), from the vertex colour (Listing 2.7) or
// the `comb` parameter, smoothed over the mesh (materials/techniques/comb_field.py).
// With FUR_FINS the outputs feed the fin geometry shader (materials/techniques/fins.geom) under vs_ names.
#include "materials/techniques/shells.glsl"

in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;
in vec3 in_tangent;
in vec3 in_binormal;
in vec4 in_comb;

#include "common/object_transform.glsl"
uniform mat4 u_projection;
uniform float u_shell_depth;
uniform float u_shell_dither = 0.0;  // geometry only: the shell moved within its slab (shells.py)
uniform float u_fur_length;     // object units, scaled per vertex by the comb alpha
uniform float u_comb_strength;
uniform sampler2D u_comb_field; // RGBA32F, texel i: vertex i's object-space comb x lean
uniform vec3 u_fur_scale;       // object axes to world units (the model matrix's scale)

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
#endif

out vec3 v_position;
out vec3 v_normal;
out vec3 v_tangent;
out vec3 v_binormal;
out vec2 v_uv;
out vec4 v_comb;
out vec4 v_base_clip;     // the base-mesh point under this shell point (Listing 2.2)
out vec4 v_tip_clip;      // the outermost-shell point: where its stipple sample was written
out float v_base_depth;   // linear view depths of those two points
out float v_tip_depth;
out float v_fur_extent;   // view-space length of the strand at this vertex
out float v_shell_depth;
out vec3 v_fur_position;  // the base point in world-scaled object space (fur volume lookups)
out vec3 v_fur_normal;    // object-space normal (triplanar weights)
out vec3 v_tip_position;  // view space (fins)
out vec3 v_base_position; // view space: the root (the deferred layers relight from it)

invariant gl_Position;

void main() {
    mat4 model_view = object_model_view();
    mat3 normal_matrix = object_normal_matrix();
    // the comb field (techniques/comb_field.py): smooth over the mesh, shorter in a crown
    int width = textureSize(u_comb_field, 0).x;
    vec3 comb = texelFetch(u_comb_field, ivec2(gl_VertexID % width, gl_VertexID / width), 0).xyz;
    comb -= dot(comb, in_normal) * in_normal;
    vec3 comb_tangent = vec3(dot(comb, in_tangent), dot(comb, in_binormal), 0.0);
    comb *= u_comb_strength;
    float fur_length = u_fur_length * in_comb.a;
    vec3 shell = in_position + shell_offset(in_normal, comb,
                                            clamp(u_shell_depth + u_shell_dither, 0.0, 1.0),
                                            fur_length);
    vec3 tip = in_position + shell_offset(in_normal, comb, 1.0, fur_length);

    vec4 position = model_view * vec4(shell, 1.0);
    vec4 base_view = model_view * vec4(in_position, 1.0);
    vec4 tip_view = model_view * vec4(tip, 1.0);
    v_position = position.xyz;
    v_normal = normalize(normal_matrix * in_normal);
    v_tangent = normalize(mat3(model_view) * in_tangent);
    v_binormal = normalize(mat3(model_view) * in_binormal);
    v_uv = in_uv;
    v_comb = vec4(comb_tangent * 0.5 + 0.5, in_comb.a);
    v_base_clip = u_projection * base_view;
    v_tip_clip = u_projection * tip_view;
    v_base_depth = -base_view.z;
    v_tip_depth = -tip_view.z;
    v_fur_extent = length(tip_view.xyz - base_view.xyz);
    v_shell_depth = u_shell_depth;
    v_fur_position = in_position * u_fur_scale;
    v_fur_normal = in_normal;
    v_tip_position = tip_view.xyz;
    v_base_position = base_view.xyz;
#if defined(SHADOW_CASTER) && !defined(OPACITY_CASTER)
    // drawn from the light (deferred.api.SHADOW_CASTER_DEFINES): the fur casts a strand's
    // length further from the light, onto other surfaces but not onto its own skin and
    // shells, whose self-shadowing is the deep opacity maps' (OPACITY_CASTER: drawn where it
    // is; deferred.lighting.shadows) or gamma(h) (materials/techniques/fur.glsl)
    position.z -= v_fur_extent;
#endif
    gl_Position = u_projection * position;
}
