// The G-buffer's render targets, in the order of deferred.gbuffer.GBUFFER_COLOR_TARGETS, then
// the G-buffer data of the material (GBUFFER_DATA_WRITE: generated per material's data).
#include "gbuffer/layout.glsl"
#include GBUFFER_DATA_WRITE

layout(location = 0) out vec4 out_albedo_specular;
layout(location = 1) out vec4 out_normal_exponent_id;
layout(location = 2) out float out_linear_depth;

void gbuffer_write(Surface s, vec3 position_view, float surface_id) {
    out_albedo_specular = vec4(clamp(s.albedo, 0.0, 1.0), clamp(s.specular_intensity, 0.0, 1.0));
    out_normal_exponent_id = vec4(octahedral_encode(normalize(s.normal)), s.specular_exponent,
                                  surface_id);
    out_linear_depth = -position_view.z;
    gbuffer_write_data(s.data);
}
