// pbr: glTF 2.0's metallic-roughness as Filament's standard model lights it. Specular: GGX
// distribution, Smith height-correlated visibility, Schlick Fresnel, times Filament's
// multiple-scattering energy compensation 1 + f0 (1 / r - 1) ("Energy loss in specular
// reflectance": r is the lobe's directional albedo for f0 = 1, the DFG table's second channel).
// Diffuse: Lambert. The G-buffer holds the base colour in albedo, metallic in
// specular_intensity, the perceptual roughness in specular_exponent and the material's ambient
// occlusion in the datum pbr_occlusion (materials/shading_models/__init__.py).
#include "common/surface.glsl"
#include "lighting/environment.glsl"

// Filament's multiscatter DFG table over (N.V, perceptual roughness), texel centres at
// (i + 0.5) / size: x = the Fresnel-weighted part of the split-sum integral (Karis's B),
// y = the whole of it for f0 = 1 (A + B); computed on the GPU (materials/shading_models/dfg.frag)
uniform sampler2D u_pbr_dfg;

const float PBR_PI = 3.14159265358979;
const float PBR_MIN_ROUGHNESS = 0.045;  // Filament's floor: a finite highlight in half floats

float pbr_distribution(float n_dot_h, float alpha) {
    float a2 = alpha * alpha;
    float d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (PBR_PI * d * d);
}

// Smith's height-correlated masking-shadowing over 4 N.L N.V (Heitz 2014)
float pbr_visibility(float n_dot_v, float n_dot_l, float alpha) {
    float a2 = alpha * alpha;
    float view = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    float light = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / max(view + light, 1e-9);
}

vec3 pbr_fresnel(vec3 f0, float v_dot_h) {
    float x = 1.0 - v_dot_h;
    float x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

struct PbrTerms {
    vec3 diffuse;          // the diffuse colour: base colour * (1 - metallic)
    vec3 f0;               // specular reflectance at normal incidence
    float roughness;       // perceptual, as glTF gives it
    float n_dot_v;
    vec2 dfg;              // the DFG table at (N.V, roughness)
    vec3 energy;           // the multiple-scattering compensation of the specular lobe
};

PbrTerms pbr_terms(Surface s, vec3 V) {
    PbrTerms t;
    float metallic = clamp(s.specular_intensity, 0.0, 1.0);
    t.diffuse = s.albedo * (1.0 - metallic);
    t.f0 = mix(vec3(0.04), s.albedo, metallic);  // glTF: a dielectric's ior of 1.5
    t.roughness = clamp(s.specular_exponent, 0.0, 1.0);
    t.n_dot_v = clamp(dot(s.normal, V), 1e-4, 1.0);
    t.dfg = texture(u_pbr_dfg, vec2(t.n_dot_v, t.roughness)).xy;
    t.energy = 1.0 + t.f0 * (1.0 / max(t.dfg.y, 1e-4) - 1.0);
    return t;
}

vec3 pbr(Surface s, vec3 L, vec3 V, vec3 radiance) {
    float n_dot_l = dot(s.normal, L);
    if (n_dot_l <= 0.0) return vec3(0.0);
    PbrTerms t = pbr_terms(s, V);
    vec3 H = normalize(L + V);
    float n_dot_h = clamp(dot(s.normal, H), 0.0, 1.0);
    float v_dot_h = clamp(dot(V, H), 0.0, 1.0);
    float roughness = max(t.roughness, PBR_MIN_ROUGHNESS);
    float alpha = roughness * roughness;
    vec3 specular = pbr_distribution(n_dot_h, alpha) * pbr_visibility(t.n_dot_v, n_dot_l, alpha) *
                    pbr_fresnel(t.f0, v_dot_h) * t.energy;
    return (t.diffuse / PBR_PI + specular) * radiance * n_dot_l;
}

// The specular lobe's share of light from all around, E = mix(B, A + B, f0) (f90 = 1).
vec3 pbr_specular_share(PbrTerms t) {
    return mix(t.dfg.xxx, t.dfg.yyy, t.f0);
}

// Lagarde and de Rousiers 2014: the share of the ambient occlusion that hides the specular lobe
float pbr_specular_occlusion(float n_dot_v, float occlusion, float roughness) {
    return clamp(pow(n_dot_v + occlusion, exp2(-16.0 * roughness - 1.0)) - 1.0 + occlusion,
                 0.0, 1.0);
}

// Light from all around: diffuse from the irradiance (over pi: the radiance a white Lambertian
// surface returns), less what the specular lobe takes; specular E times the radiance reflected
// toward the viewer (a lookup of the prefiltered environment, or the irradiance where the light
// knows no directions), as Filament's indirect light.
vec3 pbr_indirect(Surface s, PbrTerms t, vec3 irradiance, vec3 reflected) {
    float occlusion = s.occlusion * s.data.pbr_occlusion.r;
    vec3 E = pbr_specular_share(t);
    vec3 diffuse = t.diffuse * irradiance * (1.0 - E) * occlusion;
    vec3 specular = E * t.energy * reflected *
                    pbr_specular_occlusion(t.n_dot_v, occlusion, t.roughness);
    return diffuse + specular;
}

// The hemisphere light: it gives no view direction, so the surface is taken as seen head on
vec3 pbr_ambient(Surface s, vec3 irradiance) {
    PbrTerms t = pbr_terms(s, s.normal);
    return pbr_indirect(s, t, irradiance, irradiance);
}

// The image-based light (lighting/environment.glsl)
vec3 pbr_environment(Surface s, vec3 V, Environment e) {
    PbrTerms t = pbr_terms(s, V);
    vec3 R = reflect(-V, s.normal);
    return pbr_indirect(s, t, environment_irradiance(e, s.normal),
                        environment_radiance(e, R, t.roughness));
}
