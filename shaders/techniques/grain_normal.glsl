// Anisotropic grain normal (Revie 2.3.3, Listing 2.5): the normal coplanar with the eye vector
// and the grain direction, so every light's highlight stretches across the grain.
//   normal: surface normal; grain: grain (comb) direction; eye: unit vector from the eye to the
//   point. All in the same space.
vec3 grain_normal(vec3 normal, vec3 grain, vec3 eye) {
    vec3 direction = grain - dot(grain, normal) * normal;
    if (dot(direction, direction) < 1e-10) return normal;
    direction = normalize(direction);
    vec3 plane_normal = cross(eye, direction);
    if (dot(plane_normal, plane_normal) < 1e-10) return normal;  // looking along the grain
    return normalize(cross(plane_normal, direction));
}
