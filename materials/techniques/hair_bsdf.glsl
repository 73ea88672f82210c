// A hair fibre's scattering (Marschner, Jensen, Cammarano, Worley, Hanrahan 2003, "Light
// Scattering from Human Hair Fibers") in the real-time form of Karis 2016 ("Physically Based
// Hair Shading in Unreal", SIGGRAPH course): three lobes, each a longitudinal Gaussian M_p times
// an azimuthal N_p,
//   R    reflection off the cuticle: the white highlight, shifted toward the root;
//   TT   transmission through the fibre: the glow of back-lit strands, tinted by the colour;
//   TRT  one internal reflection: the coloured secondary highlight, shifted toward the tip;
// plus Karis's multiple-scattering lobe (a wrapped diffuse about the fibre mixed with
// Kajiya-Kay's |T x L|), which stands for light scattered through many strands; its colour is
// the albedo (Karis's sqrt(albedo) goes with a tint from the depth into the fur's shadow, which
// this framework does not know per light: the square root alone would lift dark colours toward grey).
// Colour becomes absorption as Karis's: a path through the fibre passes albedo^(length).
// Angles (Marschner section 2): T the strand direction root to tip, theta the angle of a
// direction to the normal plane of T (sin theta = T.w), phi the azimuth between the light's and
// the view's projections onto that plane, theta_h = (theta_i + theta_r) / 2 and
// theta_d = (theta_r - theta_i) / 2. The result multiplies the light's radiance (this
// framework's convention: a Lambertian surface answers albedo * N.L, so the lobes carry pi).
// No includes: tests/materials/shading_models/test_marschner.py evaluates this file against numpy.

#define HAIR_PI 3.14159265
#define HAIR_ETA 1.55           // the fibre's index of refraction
#define HAIR_TILT -0.06         // alpha, the cuticle scales' tilt (radians; Marschner: -5..-10 deg)
#define HAIR_SCATTER 0.6        // weight of the multiple-scattering lobe

// Marschner's longitudinal lobe: a unit-area Gaussian of width beta.
float hair_gaussian(float beta, float x) {
    return exp(-0.5 * x * x / (beta * beta)) / (sqrt(2.0 * HAIR_PI) * beta);
}

// Schlick's Fresnel for the fibre (n = HAIR_ETA) at cos(angle of incidence).
float hair_fresnel(float cos_angle) {
    float f0 = (1.0 - HAIR_ETA) / (1.0 + HAIR_ETA);
    f0 *= f0;
    float m = clamp(1.0 - cos_angle, 0.0, 1.0);
    return f0 + (1.0 - f0) * m * m * m * m * m;
}

// (R + TT + TRT, multiple scattering) toward V of light from L: T unit strand direction, L and
// V unit, toward the light and the viewer; albedo the fibre's colour; beta the longitudinal
// roughness (radians); specular scales R.
vec3 hair_lobes(vec3 T, vec3 L, vec3 V, vec3 albedo, float beta, float specular,
                out vec3 scatter) {
    float sin_i = clamp(dot(T, L), -1.0, 1.0);
    float sin_r = clamp(dot(T, V), -1.0, 1.0);
    float theta_i = asin(sin_i);
    float theta_r = asin(sin_r);
    float theta_h = 0.5 * (theta_i + theta_r);
    float cos_d = max(cos(0.5 * (theta_r - theta_i)), 1e-3);
    vec3 lp = L - sin_i * T;
    vec3 vp = V - sin_r * T;
    float cos_phi = dot(lp, vp) * inversesqrt(dot(lp, lp) * dot(vp, vp) + 1e-4);
    float cos_half_phi = sqrt(clamp(0.5 + 0.5 * cos_phi, 0.0, 1.0));
    vec3 colour = max(albedo, vec3(1e-4));

    // R: Marschner's alpha_R = alpha, beta_R = beta; N_R = cos(phi/2)/4 * F at the half angle
    float m_r = hair_gaussian(beta, theta_h - HAIR_TILT);
    float n_r = 0.25 * cos_half_phi * hair_fresnel(sqrt(clamp(0.5 + 0.5 * dot(L, V), 0.0, 1.0)));
    vec3 r = vec3(specular * m_r * n_r);

    // TT: alpha_TT = -alpha/2, beta_TT = beta/2; Karis's fitted h, attenuation and
    // azimuthal lobe about phi = pi (eta' = Bravais' index, fitted)
    float eta_p = 1.19 / cos_d + 0.36 * cos_d;
    float a = 1.0 / eta_p;
    float h = cos_half_phi * (1.0 + a * (0.6 - 0.8 * cos_phi));
    float f_tt = hair_fresnel(cos_d * sqrt(clamp(1.0 - h * h, 0.0, 1.0)));
    vec3 t_tt = pow(colour, vec3(0.5 * sqrt(clamp(1.0 - h * h * a * a, 0.0, 1.0)) / cos_d));
    float m_tt = hair_gaussian(0.5 * beta, theta_h + 0.5 * HAIR_TILT);
    float n_tt = exp(-3.65 * cos_phi - 3.98);
    vec3 tt = m_tt * n_tt * (1.0 - f_tt) * (1.0 - f_tt) * t_tt;

    // TRT: alpha_TRT = -3 alpha/2, beta_TRT = 2 beta; h fixed at sqrt(3)/2 (Karis)
    float f_trt = hair_fresnel(0.5 * cos_d);
    vec3 t_trt = pow(colour, vec3(0.8 / cos_d));
    float m_trt = hair_gaussian(2.0 * beta, theta_h + 1.5 * HAIR_TILT);
    float n_trt = exp(17.0 * cos_phi - 16.78);
    vec3 trt = m_trt * n_trt * (1.0 - f_trt) * (1.0 - f_trt) * f_trt * t_trt;

    // multiple scattering: wrapped diffuse about the normal facing the viewer, mixed with
    // Kajiya-Kay's |T x L| ~ 1 - |T.L|
    vec3 facing = vp * inversesqrt(dot(vp, vp) + 1e-8);
    float wrapped = clamp((dot(facing, L) + 1.0) / 4.0, 0.0, 1.0);
    float diffuse = mix(wrapped, 1.0 - abs(sin_i), 0.33);
    scatter = HAIR_SCATTER * diffuse * colour;
    return HAIR_PI * (r + tt + trt);
}

vec3 hair_bsdf(vec3 T, vec3 L, vec3 V, vec3 albedo, float beta, float specular) {
    vec3 scatter;
    vec3 single = hair_lobes(T, L, V, albedo, beta, specular, scatter);
    return single + scatter;
}

// The ambient's answer: the multiple-scattering lobe averaged over the sphere of directions,
// relative to a Lambertian surface's (which answers albedo * irradiance): the wrapped term
// averages 1/4 and |T x L| ~ 1 - |T.L| averages 1/2, against N.L's 1/4.
vec3 hair_ambient(vec3 albedo, vec3 irradiance) {
    float average = mix(0.25, 0.5, 0.33) / 0.25;
    return irradiance * HAIR_SCATTER * average * max(albedo, vec3(0.0));
}
