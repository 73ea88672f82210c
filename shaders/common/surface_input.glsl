// Fragment-side inputs of common/mesh.vert, gathered into a SurfaceInput.
#include "common/surface.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec3 v_tangent;
in vec3 v_binormal;
in vec2 v_uv;
in vec4 v_comb;

SurfaceInput surface_input() {
    SurfaceInput i;
    i.position = v_position;
    i.normal = normalize(v_normal);
    i.tangent = normalize(v_tangent);
    i.binormal = normalize(v_binormal);
    i.uv = v_uv;
    i.comb = v_comb;
    return i;
}
