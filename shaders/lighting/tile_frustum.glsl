// A screen tile's frustum for the light culling shaders: its four side planes through the eye
// (view space), and the test of a light's bounding sphere against them.
uniform mat4 u_inverse_projection;
uniform vec2 u_resolution;

// The ray through a pixel-space point (at the far plane), view space.
vec3 view_ray(vec2 pixel) {
    vec2 ndc = pixel / u_resolution * 2.0 - 1.0;
    vec4 ray = u_inverse_projection * vec4(ndc, 1.0, 1.0);
    return ray.xyz / ray.w;
}

// The side planes of the tile spanning pixels [origin, end), normals pointing into the tile.
void tile_planes(ivec2 origin, ivec2 end, out vec3 planes[4]) {
    vec3 r00 = view_ray(vec2(origin));
    vec3 r10 = view_ray(vec2(end.x, origin.y));
    vec3 r01 = view_ray(vec2(origin.x, end.y));
    vec3 r11 = view_ray(vec2(end));
    vec3 centre = r00 + r10 + r01 + r11;
    planes[0] = normalize(cross(r01, r00));
    planes[1] = normalize(cross(r10, r11));
    planes[2] = normalize(cross(r00, r10));
    planes[3] = normalize(cross(r11, r01));
    for (int k = 0; k < 4; ++k)
        if (dot(planes[k], centre) < 0.0) planes[k] = -planes[k];
}

// Whether the sphere (view-space centre, radius) is not wholly outside any of the four planes.
bool sphere_touches_planes(vec3 planes[4], vec4 sphere) {
    return dot(planes[0], sphere.xyz) >= -sphere.w && dot(planes[1], sphere.xyz) >= -sphere.w &&
           dot(planes[2], sphere.xyz) >= -sphere.w && dot(planes[3], sphere.xyz) >= -sphere.w;
}
