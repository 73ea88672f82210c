// G-buffer encoding and decoding; the format is documented in deferred/gbuffer/layout.py.
#include "common/surface.glsl"
#include "gbuffer/octahedral.glsl"

struct GBufferSample {
    Surface surface;
    float surface_id;    // shading model * MATERIAL_IDS + material id; 0 = background
    float material_id;   // the material's registry id; 0 = background
    float linear_depth;  // -z_view
};

GBufferSample gbuffer_decode(vec4 albedo_specular, vec4 normal_exponent_id, float linear_depth) {
    GBufferSample g;
    g.surface.albedo = albedo_specular.rgb;
    g.surface.specular_intensity = albedo_specular.a;
    g.surface.normal = octahedral_decode(normal_exponent_id.xy);
    g.surface.specular_exponent = normal_exponent_id.z;
    g.surface.occlusion = 1.0;
    g.surface.view_depth = linear_depth;
    g.surface.shading_model = surface_shading_model(normal_exponent_id.w);
    g.surface_id = normal_exponent_id.w;
    g.material_id = surface_material_id(normal_exponent_id.w);
    g.linear_depth = linear_depth;
    return g;
}

// Whether a G-buffer id is that of the surface `surface_id` (stipple and shell lookups).
bool same_surface(float stored_id, float surface_id) {
    return abs(stored_id - surface_id) < 0.5;
}

// View-space position of a pixel from its linear depth: position is never stored.
vec3 view_position(vec2 frag_coord, float linear_depth, vec2 resolution, mat4 inverse_projection) {
    vec2 ndc = frag_coord / resolution * 2.0 - 1.0;
    vec4 ray = inverse_projection * vec4(ndc, 1.0, 1.0);
    ray.xyz /= ray.w;
    return ray.xyz * (linear_depth / -ray.z);
}
