// Silva et al. 3.2: a layer at normalized fur length h is the base surface displaced by
// v_offset(h) = beta(h) + phi(h) (Eq. 1).
//
// beta(h), the strand's bend (3.2.1): a quadratic Bezier from p_root to the simulated tip p. Its
// control point is the rest strand's midpoint (p_root + p_0) / 2, so the strand leaves the root
// along the normal, unbent layers sit evenly along it (B(h) = p_root + h L n when p = p_0: the
// fur volume's slices and the layers' opacities assume even layers), and layer h bends by h^2
// of the tip's deflection. (With p_0 itself as the control point, unbent layers would bunch at
// the tip, at heights (2h - h^2) L.)
//
// phi(h), the curl (3.2.2, Eq. 4): alpha(h) (cos(w h) u + sin(w h) v) in the surface's tangent
// plane, alpha(h) = (1 - rho) K h: the strand winds round a widening helix, and wet fur (rho 1)
// loses its curl.

// beta(h): the layer's offset from the root along the strand's Bezier.
vec3 strand_bend(vec3 root, vec3 rest_tip, vec3 tip, float h) {
    vec3 control = 0.5 * (root + rest_tip);
    float s = 1.0 - h;
    return s * s * root + 2.0 * s * h * control + h * h * tip - root;
}

// d beta / dh.
vec3 strand_bend_derivative(vec3 root, vec3 rest_tip, vec3 tip, float h) {
    vec3 control = 0.5 * (root + rest_tip);
    return 2.0 * (1.0 - h) * (control - root) + 2.0 * h * (tip - control);
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
