// The pbr material (materials/pbr): glTF 2.0's metallic-roughness surface. Its textures are
// each sampled through texture_lookup: the UV set chosen, KHR_texture_transform applied in
// glTF's texture space (v down from the image's top: the framework's v is 1 - glTF's), the
// mirrored wraps folded here (GL holds repeat or clamp), the mip level from the unfolded
// coordinates. Besides the Surface it leaves the emission and the alpha in pbr_emitted and
// pbr_alpha (the forward and emission passes read them); ALPHA_MASK cuts below the cutoff.
#include "common/surface.glsl"

uniform vec4 u_base_color;
uniform float u_metallic;
uniform float u_roughness;
uniform vec3 u_emissive;
uniform float u_emissive_strength;
uniform float u_normal_scale;
uniform float u_occlusion_strength;
uniform float u_alpha_cutoff;

vec3 pbr_emitted;
float pbr_alpha;

vec4 texture_lookup(sampler2D map, SurfaceInput i, int set, vec3 row_u, vec3 row_v,
                    vec2 mirror) {
    vec2 uv = set == 1 ? i.uv1 : i.uv;
    vec3 gltf = vec3(uv.x, 1.0 - uv.y, 1.0);
    vec2 st = vec2(dot(row_u, gltf), dot(row_v, gltf));
    vec2 folded = mix(st, 1.0 - abs(mod(st, 2.0) - 1.0), mirror);
    vec2 at = vec2(folded.x, 1.0 - folded.y);
    vec2 unfolded = vec2(st.x, 1.0 - st.y);
    return textureGrad(map, at, dFdx(unfolded), dFdy(unfolded));
}

// Each texture: its sampler, UV set, KHR_texture_transform's rows and which wraps are
// mirrored (1), read through texture_lookup
#ifdef HAS_BASE_COLOR_TEXTURE
uniform sampler2D u_base_color_texture;
uniform int u_base_color_uv;
uniform vec3 u_base_color_transform_u;
uniform vec3 u_base_color_transform_v;
uniform vec2 u_base_color_mirror;
#endif
#ifdef HAS_METALLIC_ROUGHNESS_TEXTURE
uniform sampler2D u_metallic_roughness_texture;
uniform int u_metallic_roughness_uv;
uniform vec3 u_metallic_roughness_transform_u;
uniform vec3 u_metallic_roughness_transform_v;
uniform vec2 u_metallic_roughness_mirror;
#endif
#ifdef HAS_NORMAL_TEXTURE
uniform sampler2D u_normal_texture;
uniform int u_normal_uv;
uniform vec3 u_normal_transform_u;
uniform vec3 u_normal_transform_v;
uniform vec2 u_normal_mirror;
#endif
#ifdef HAS_OCCLUSION_TEXTURE
uniform sampler2D u_occlusion_texture;
uniform int u_occlusion_uv;
uniform vec3 u_occlusion_transform_u;
uniform vec3 u_occlusion_transform_v;
uniform vec2 u_occlusion_mirror;
#endif
#ifdef HAS_EMISSIVE_TEXTURE
uniform sampler2D u_emissive_texture;
uniform int u_emissive_uv;
uniform vec3 u_emissive_transform_u;
uniform vec3 u_emissive_transform_v;
uniform vec2 u_emissive_mirror;
#endif

Surface material_surface(SurfaceInput i) {
    vec4 base = u_base_color * i.color;
#ifdef HAS_BASE_COLOR_TEXTURE
    base *= texture_lookup(u_base_color_texture, i, u_base_color_uv, u_base_color_transform_u,
                           u_base_color_transform_v, u_base_color_mirror);
#endif
    pbr_alpha = base.a;
#ifdef ALPHA_MASK
    if (base.a < u_alpha_cutoff) discard;
    pbr_alpha = 1.0;
#elif !defined(ALPHA_BLEND)
    pbr_alpha = 1.0;
#endif
    float metallic = u_metallic;
    float roughness = u_roughness;
#ifdef HAS_METALLIC_ROUGHNESS_TEXTURE
    vec4 metal_rough = texture_lookup(
        u_metallic_roughness_texture, i, u_metallic_roughness_uv,
        u_metallic_roughness_transform_u, u_metallic_roughness_transform_v,
        u_metallic_roughness_mirror);
    metallic *= metal_rough.b;
    roughness *= metal_rough.g;
#endif
    vec3 N = i.normal;
    vec3 T = i.tangent;
    // MikkTSpace's per-pixel bitangent: cross(N, T) with the interpolated frame's handedness
    vec3 B = cross(N, T) * (dot(cross(N, T), i.binormal) < 0.0 ? -1.0 : 1.0);
#ifdef DOUBLE_SIDED
    if (!gl_FrontFacing) {  // the back face's frame turned round, as glTF's viewer does
        N = -N;
        T = -T;
        B = -B;
    }
#endif
#ifdef HAS_NORMAL_TEXTURE
    vec3 n = texture_lookup(u_normal_texture, i, u_normal_uv, u_normal_transform_u,
                            u_normal_transform_v, u_normal_mirror).xyz * 2.0 - 1.0;
    n.xy *= u_normal_scale;
    N = normalize(T * n.x + B * n.y + N * n.z);
#endif
    float occlusion = 1.0;
#ifdef HAS_OCCLUSION_TEXTURE
    float ao = texture_lookup(u_occlusion_texture, i, u_occlusion_uv, u_occlusion_transform_u,
                              u_occlusion_transform_v, u_occlusion_mirror).r;
    occlusion = 1.0 + u_occlusion_strength * (ao - 1.0);
#endif
    pbr_emitted = u_emissive * u_emissive_strength;
#ifdef HAS_EMISSIVE_TEXTURE
    pbr_emitted *= texture_lookup(u_emissive_texture, i, u_emissive_uv, u_emissive_transform_u,
                                  u_emissive_transform_v, u_emissive_mirror).rgb;
#endif
    Surface s;
    s.albedo = base.rgb;
    s.specular_intensity = metallic;
    s.specular_exponent = roughness;
    s.normal = N;
    s.data.pbr_occlusion = vec4(occlusion, 0.0, 0.0, 0.0);
    return s;
}
