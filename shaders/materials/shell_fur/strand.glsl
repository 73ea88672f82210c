// Silva et al. 3.2: a layer at normalized fur length h is the base surface displaced by
// v_offset(h) = beta(h) + phi(h) (Eq. 1).
//
// beta(h), the strand's bend (3.2.1): the quadratic Bezier through p_root, p_0 (the rest tip,
// the control point) and p (the simulated tip). It is sampled at t = 1 - sqrt(1 - h), which puts
// the layers of unbent fur evenly along the normal (B(t) = p_root + (2t - t^2) L n = p_root + h L n
// when p = p_0), as the fur volume's slices and the shells' opacities assume.
//
// phi(h), the curl (3.2.2, Eq. 4): alpha(h) (cos(w h) u + sin(w h) v) in the surface's tangent
// plane, alpha(h) = (1 - rho) K h: the strand winds round a widening helix, and wet fur (rho 1)
// loses its curl.

float bezier_parameter(float h) {
    return 1.0 - sqrt(max(1.0 - h, 0.0));
}

// beta(h): the layer's offset from the root along the strand's Bezier.
vec3 strand_bend(vec3 root, vec3 rest_tip, vec3 tip, float h) {
    float t = bezier_parameter(h);
    float s = 1.0 - t;
    return s * s * root + 2.0 * s * t * rest_tip + t * t * tip - root;
}

// d beta / dh: dB/dt = 2(1 - t)(p_0 - p_root) + 2t(p - p_0) times dt/dh = 1 / (2(1 - t)); t is
// kept below 1, where dt/dh grows without bound (only the direction is used).
vec3 strand_bend_derivative(vec3 root, vec3 rest_tip, vec3 tip, float h) {
    float t = min(bezier_parameter(h), 0.98);
    return (rest_tip - root) + t / (1.0 - t) * (tip - rest_tip);
}

// phi(h), Eq. 4.
vec3 curl_offset(float h, float wetness, float radius, float frequency, vec3 u, vec3 v) {
    float alpha = (1.0 - wetness) * radius * h;
    return alpha * (cos(frequency * h) * u + sin(frequency * h) * v);
}

// d phi / dh.
vec3 curl_derivative(float h, float wetness, float radius, float frequency, vec3 u, vec3 v) {
    float k = (1.0 - wetness) * radius;
    float wh = frequency * h;
    return k * ((cos(wh) - wh * sin(wh)) * u + (sin(wh) + wh * cos(wh)) * v);
}

// The simulated tip kept inside Eq. 3's region (no farther than L from the root, not below the
// surface): vertices average the tips of their triangles, which may stray a little outside.
vec3 constrain_tip(vec3 root, vec3 normal, float length_, vec3 tip) {
    vec3 offset = tip - root;
    offset -= min(dot(offset, normal), 0.0) * normal;
    float l = length(offset);
    return l > length_ ? root + offset * (length_ / l) : root + offset;
}
