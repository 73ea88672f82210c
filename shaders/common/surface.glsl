// The surface interface between materials and lights (the G-buffer's contents, decoded).
// A material's surface file defines: Surface material_surface(SurfaceInput i);

struct SurfaceInput {
    vec3 position;   // view space
    vec3 normal;     // view space, unit
    vec3 tangent;    // view space, unit, along +U
    vec3 binormal;   // view space, unit, along +V
    vec2 uv;
    vec4 comb;       // tangent-space comb direction packed to [0, 1], fur length scale (Revie 2.4.1)
};

struct Surface {
    vec3 albedo;               // linear RGB
    float specular_intensity;  // [0, 1]
    float specular_exponent;   // Blinn-Phong exponent
    vec3 normal;               // view space, unit: the normal lights use
    float occlusion;           // ambient occlusion [0, 1]; set by the pipeline, not the material
};
