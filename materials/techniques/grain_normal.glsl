// Anisotropic grain normal (Revie 2.3.3, Listing 2.5): the normal coplanar with the eye vector
// and the grain direction, so every light's highlight stretches across the grain.
//   normal: surface normal; grain: grain (comb) direction; eye: unit vector from the eye to the
//   point. All in the same space.
vec3 grain_normal(vec3 normal, vec3 grain, vec3 eye) {
    vec3 direction = grain - dot(grain, normal) * normal;
    if (dot(direction, direction) < 1e-10) return normal;
    direction = normalize(direction);
    vec3 plane_normal = cross(eye, direction);
    float across = length(plane_normal);  // sine of the angle between the eye and the grain
    if (across < 1e-5) return normal;  // looking along the grain
    vec3 bent = normalize(cross(plane_normal, direction));
    // Looking nearly along the grain the plane turns half a turn across a few pixels (strands
    // pointing at the eye from a crown): fade to the surface normal there, or the highlight
    // flips from one side to the other along a line.
    return normalize(mix(normal, bent, smoothstep(0.0, 0.35, across)));
}
