// Rim scattering by bent normals (Revie 2.3.2, Listing 2.3): near silhouettes the normal is
// pushed away from the viewer so the pixel samples light arriving from behind the object.
//   silhouette_normal: the geometric normal deciding how close to the silhouette we are;
//   normal: the normal to bend; eye: unit vector from the eye to the point.
vec3 rim_bend(vec3 silhouette_normal, vec3 normal, vec3 eye, float strength, float falloff) {
    float n_dot_v = clamp(dot(silhouette_normal, -eye), 0.0, 1.0);
    float rim_weight = strength * pow(1.0 - n_dot_v, falloff);
    return normalize(normal + eye * rim_weight);
}
