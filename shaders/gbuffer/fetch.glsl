// Read the G-buffer at a pixel (lights and screen passes), declared data included.
#include "gbuffer/layout.glsl"
#include "generated/gbuffer_data_fetch.glsl"

uniform sampler2D u_albedo_specular;
uniform sampler2D u_normal_exponent_id;
uniform sampler2D u_linear_depth;

GBufferSample gbuffer_fetch(ivec2 pixel) {
    GBufferSample g = gbuffer_decode(texelFetch(u_albedo_specular, pixel, 0),
                                     texelFetch(u_normal_exponent_id, pixel, 0),
                                     texelFetch(u_linear_depth, pixel, 0).r);
    g.surface.data = gbuffer_fetch_data(pixel);
    return g;
}
