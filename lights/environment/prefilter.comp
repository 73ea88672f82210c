// One level of the GGX-prefiltered cube into a buffer: at each texel's direction N (= V = R,
// Karis's split-sum assumption), the source's radiance averaged over GGX-distributed half
// vectors of this level's roughness, weighted by N.L; each sample read from the source's mip
// level whose texels cover the sample's solid angle (filtered importance sampling, Colbert and
// Krivanek, GPU Gems 3 ch. 20), so few samples make no noise. Roughness 0 is the source itself.
#include "lights/environment/directions.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(std430, binding = 0) writeonly buffer Texels { vec4 texels[]; };

uniform samplerCube u_source;   // the map at u_source_size, its mips box-filtered
uniform float u_source_size;
uniform int u_size;             // this level's
uniform int u_first;            // this level's first texel in the buffer
uniform float u_roughness;      // perceptual
uniform int u_samples;

vec2 hammersley(uint i, uint count) {
    uint bits = i;
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return vec2(float(i) / float(count), float(bits) * 2.3283064365386963e-10);
}

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= u_size || id.y >= u_size) return;
    vec3 N = cube_direction(id.z, (vec2(id.xy) + 0.5) / float(u_size));
    vec3 color;
    if (u_roughness <= 0.0) {
        color = textureLod(u_source, N, 0.0).rgb;
    } else {
        float alpha = u_roughness * u_roughness;
        float a2 = alpha * alpha;
        vec3 up = abs(N.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
        vec3 T = normalize(cross(up, N));
        vec3 B = cross(N, T);
        float texel_solid_angle = 4.0 * ENVIRONMENT_PI / (6.0 * u_source_size * u_source_size);
        vec3 total = vec3(0.0);
        float weight = 0.0;
        for (int k = 0; k < u_samples; ++k) {
            vec2 xi = hammersley(uint(k), uint(u_samples));
            float cos_theta = sqrt((1.0 - xi.x) / (1.0 + (a2 - 1.0) * xi.x));
            float sin_theta = sqrt(1.0 - cos_theta * cos_theta);
            float phi = 2.0 * ENVIRONMENT_PI * xi.y;
            vec3 H = T * (sin_theta * cos(phi)) + B * (sin_theta * sin(phi)) + N * cos_theta;
            vec3 L = 2.0 * dot(N, H) * H - N;
            float n_dot_l = dot(N, L);
            if (n_dot_l <= 0.0) continue;
            // pdf of L: D(h) (N.H) / (4 V.H), with V = N: D / 4
            float d = cos_theta * cos_theta * (a2 - 1.0) + 1.0;
            float pdf = a2 / (ENVIRONMENT_PI * d * d) * 0.25;
            float sample_solid_angle = 1.0 / (float(u_samples) * pdf + 1e-6);
            float lod = max(0.5 * log2(sample_solid_angle / texel_solid_angle) + 1.0, 0.0);
            total += textureLod(u_source, L, lod).rgb * n_dot_l;
            weight += n_dot_l;
        }
        color = total / max(weight, 1e-6);
    }
    texels[u_first + (id.z * u_size + id.y) * u_size + id.x] = vec4(color, 1.0);
}
