// Fragment-side inputs of common/mesh.vert, gathered into a SurfaceInput, and the material's
// surface completed with what the framework owns (shading model, occlusion).
#include "common/surface.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec3 v_tangent;
in vec3 v_binormal;
in vec2 v_uv;
in vec4 v_comb;
#ifdef MESH_EXTRAS
in vec2 v_uv1;
in vec4 v_color;
#endif

uniform float u_surface_id;  // this object's G-buffer id: shading model and material

SurfaceInput surface_input() {
    SurfaceInput i;
    i.position = v_position;
    i.normal = normalize(v_normal);
    i.tangent = normalize(v_tangent);
    i.binormal = normalize(v_binormal);
    i.uv = v_uv;
    i.comb = v_comb;
#ifdef MESH_EXTRAS
    i.uv1 = v_uv1;
    i.color = v_color;
#endif
    return i;
}

Surface material_surface(SurfaceInput i);  // defined by the material's SURFACE_FILE

Surface evaluate_surface(SurfaceInput i) {
    Surface s = material_surface(i);
    s.shading_model = surface_shading_model(u_surface_id);
    s.occlusion = 1.0;
    return s;
}
