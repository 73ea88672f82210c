// The map's radiance projected on the 9 real spherical harmonics l <= 2 (one invocation a
// coefficient, summing the map's texels at u_lod with their solid angles), the cosine lobe
// convolved in and divided by pi (Ramamoorthi and Hanrahan 2001: 1, 2/3, 1/4 by band): the
// coefficients of the irradiance over pi that lighting/environment.glsl evaluates.
#include "lights/environment/directions.glsl"
#include "lighting/environment.glsl"
layout(local_size_x = 1, local_size_y = 1, local_size_z = 1) in;
layout(std430, binding = 0) writeonly buffer Coefficients { vec4 coefficients[9]; };

uniform sampler2D u_equirect;
uniform int u_lod;

void main() {
    int k = int(gl_GlobalInvocationID.x);
    ivec2 size = textureSize(u_equirect, u_lod);
    vec3 total = vec3(0.0);
    float texel = (2.0 * ENVIRONMENT_PI / float(size.x)) * (ENVIRONMENT_PI / float(size.y));
    float y[9];
    for (int j = 0; j < size.y; ++j) {
        float theta = (1.0 - (float(j) + 0.5) / float(size.y)) * ENVIRONMENT_PI;
        float solid_angle = texel * sin(theta);
        for (int i = 0; i < size.x; ++i) {
            vec3 d = equirect_direction((vec2(i, j) + 0.5) / vec2(size));
            environment_sh_basis(d, y);
            total += texelFetch(u_equirect, ivec2(i, j), u_lod).rgb * y[k] * solid_angle;
        }
    }
    float band = k == 0 ? 1.0 : (k < 4 ? 2.0 / 3.0 : 0.25);
    coefficients[k] = vec4(total * band, 0.0);
}
