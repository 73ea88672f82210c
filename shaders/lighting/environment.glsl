// The image-based light's lookups (lights/environment): an equirectangular map made, on the GPU
// once, into 9 spherical-harmonic coefficients of its irradiance and a cube map whose mip levels
// hold it prefiltered by GGX lobes of growing roughness (the split-sum's first factor; a
// shading model's environment function brings the second, its DFG table). Directions here are
// view space; an Environment turns them into the map's.

// GGX-prefiltered radiance: mip k for perceptual roughness k / max_lod (linear between levels)
uniform samplerCube u_environment_specular;
// 9 x 1: the irradiance over pi (the cosine lobe convolved in, so a white Lambertian surface
// returns it) as coefficients of the real spherical harmonics l <= 2, in the map's frame
uniform sampler2D u_environment_sh;

struct Environment {
    mat3 to_map;    // view space -> the map's directions (the camera undone, the light's rotation)
    vec3 scale;     // colour * intensity
    float max_lod;  // the prefiltered cube's last mip level: roughness 1
};

// The real spherical harmonics l <= 2 at unit d, in the order of u_environment_sh
void environment_sh_basis(vec3 d, out float y[9]) {
    y[0] = 0.282095;
    y[1] = 0.488603 * d.y;
    y[2] = 0.488603 * d.z;
    y[3] = 0.488603 * d.x;
    y[4] = 1.092548 * d.x * d.y;
    y[5] = 1.092548 * d.y * d.z;
    y[6] = 0.315392 * (3.0 * d.z * d.z - 1.0);
    y[7] = 1.092548 * d.x * d.z;
    y[8] = 0.546274 * (d.x * d.x - d.y * d.y);
}

// Irradiance over pi arriving at a surface of view-space normal N
vec3 environment_irradiance(Environment e, vec3 N) {
    float y[9];
    environment_sh_basis(normalize(e.to_map * N), y);
    vec3 total = vec3(0.0);
    for (int k = 0; k < 9; ++k) {
        total += y[k] * texelFetch(u_environment_sh, ivec2(k, 0), 0).rgb;
    }
    return max(total, vec3(0.0)) * e.scale;
}

// Radiance arriving from view-space direction R through a GGX lobe of perceptual roughness
vec3 environment_radiance(Environment e, vec3 R, float roughness) {
    float lod = clamp(roughness, 0.0, 1.0) * e.max_lod;
    return textureLod(u_environment_specular, e.to_map * R, lod).rgb * e.scale;
}
