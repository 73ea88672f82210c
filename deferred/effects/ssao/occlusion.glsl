// Screen-space ambient occlusion at one G-buffer point: a normal-oriented hemisphere of samples
// in view space, rotated per grid cell by interleaved gradient noise; a sample counts when the
// G-buffer surface is in front of it.
uniform sampler2D u_linear_depth;
uniform sampler2D u_normal_exponent_id;
uniform vec2 u_resolution;
uniform mat4 u_projection;
uniform mat4 u_inverse_projection;
uniform float u_radius;
uniform float u_strength;
uniform int u_samples;

const float GOLDEN_ANGLE = 2.39996323;

// The open fraction at full-resolution pixel `pixel` (centre `frag_coord`, linear depth
// `depth` > 0); `noise_coord` is the cell of the grid the result is blurred on.
float ssao_occlusion(vec2 frag_coord, ivec2 pixel, float depth, vec2 noise_coord) {
    vec3 P = view_position(frag_coord, depth, u_resolution, u_inverse_projection);
    vec3 N = octahedral_decode(texelFetch(u_normal_exponent_id, pixel, 0).xy);
    float noise = fract(52.9829189 * fract(dot(noise_coord, vec2(0.06711056, 0.00583715))));
    vec3 helper = abs(N.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    vec3 T = normalize(cross(helper, N));
    vec3 B = cross(N, T);
    float occluded = 0.0;
    for (int k = 0; k < u_samples; ++k) {
        // Spiral over the hemisphere, denser near the centre and near the point.
        float t = (float(k) + 0.5) / float(u_samples);
        float angle = float(k) * GOLDEN_ANGLE + noise * 6.2831853;
        float r = sqrt(t);
        vec3 direction = T * (cos(angle) * r) + B * (sin(angle) * r) + N * sqrt(1.0 - t);
        float scale = mix(0.1, 1.0, t * t);
        vec3 Q = P + direction * (u_radius * scale);
        vec4 clip = u_projection * vec4(Q, 1.0);
        ivec2 sample_pixel = ivec2(floor((clip.xy / clip.w * 0.5 + 0.5) * u_resolution));
        if (any(lessThan(sample_pixel, ivec2(0))) ||
            any(greaterThanEqual(sample_pixel, ivec2(u_resolution)))) continue;
        float scene_depth = texelFetch(u_linear_depth, sample_pixel, 0).r;
        if (scene_depth <= 0.0) continue;
        float range = smoothstep(0.0, 1.0, u_radius / max(abs(depth - scene_depth), 1e-4));
        occluded += (scene_depth < -Q.z - 0.02 * u_radius ? 1.0 : 0.0) * range;
    }
    return clamp(1.0 - u_strength * occluded / float(u_samples), 0.0, 1.0);
}
