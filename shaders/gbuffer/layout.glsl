// G-buffer encoding and decoding; the format is documented in deferred/gbuffer.py.
#include "common/surface.glsl"

// Octahedral normal encoding (Cigolle et al. 2014): a unit vector in two signed values.
vec2 octahedral_wrap(vec2 v) {
    return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

vec2 octahedral_encode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    return n.z >= 0.0 ? n.xy : octahedral_wrap(n.xy);
}

vec3 octahedral_decode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = octahedral_wrap(n.xy);
    return normalize(n);
}

struct GBufferSample {
    Surface surface;
    float material_id;   // 0 = background
    float linear_depth;  // -z_view
};

GBufferSample gbuffer_decode(vec4 albedo_specular, vec4 normal_exponent_id, float linear_depth) {
    GBufferSample g;
    g.surface.albedo = albedo_specular.rgb;
    g.surface.specular_intensity = albedo_specular.a;
    g.surface.normal = octahedral_decode(normal_exponent_id.xy);
    g.surface.specular_exponent = normal_exponent_id.z;
    g.surface.occlusion = 1.0;
    g.material_id = normal_exponent_id.w;
    g.linear_depth = linear_depth;
    return g;
}

// View-space position of a pixel from its linear depth: position is never stored.
vec3 view_position(vec2 frag_coord, float linear_depth, vec2 resolution, mat4 inverse_projection) {
    vec2 ndc = frag_coord / resolution * 2.0 - 1.0;
    vec4 ray = inverse_projection * vec4(ndc, 1.0, 1.0);
    ray.xyz /= ray.w;
    return ray.xyz * (linear_depth / -ray.z);
}
