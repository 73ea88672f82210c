// The surface interface between materials and lights (the G-buffer's contents, decoded).
// A material's surface file defines: Surface material_surface(SurfaceInput i);
#include "generated/gbuffer_data.glsl"

struct SurfaceInput {
    vec3 position;   // view space
    vec3 normal;     // view space, unit
    vec3 tangent;    // view space, unit, along +U
    vec3 binormal;   // view space, unit, along +V
    vec2 uv;
    vec4 comb;       // tangent-space comb direction packed to [0, 1], fur length scale (Revie 2.4.1)
#ifdef MESH_EXTRAS
    vec2 uv1;        // the second UV set (the first where the mesh has none)
    vec4 color;      // the vertex colour, linear RGBA (white where the mesh has none)
#endif
};

struct Surface {
    vec3 albedo;               // linear RGB
    float specular_intensity;  // [0, 1]
    float specular_exponent;   // Blinn-Phong exponent (its analogue in other shading models)
    vec3 normal;               // view space, unit: the normal lights use
    float occlusion;           // ambient occlusion [0, 1]; set by the pipeline, not the material
    int shading_model;         // the BRDF lights call; set by the framework from u_surface_id
    float view_depth;          // -z in view space; set by the framework where lights shade
    SurfaceData data;          // G-buffer data the scene's materials declare, by name
};

// The G-buffer id channel packs shading model * MATERIAL_IDS + material id
// (deferred.gbuffer.surface_id, which generates the constant).
#include "generated/surface_id.glsl"

int surface_shading_model(float surface_id) {
    return int(floor((surface_id + 0.5) / MATERIAL_IDS));
}

float surface_material_id(float surface_id) {
    return mod(floor(surface_id + 0.5), MATERIAL_IDS);
}
