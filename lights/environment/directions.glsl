// Directions of the environment's maps (lights/environment/maps.py), in the map's frame (+Y up).
// Equirectangular: u = 0.5 + atan(x, -z) / 2pi (the image's middle column looks along -Z),
// v = acos(y) / pi from the top row; the texture holds the image bottom row first (t = 1 - v).
// Cube faces in GL's order +X, -X, +Y, -Y, +Z, -Z, (s, t) as GL looks them up.

const float ENVIRONMENT_PI = 3.14159265358979;

vec2 equirect_st(vec3 d) {
    d = normalize(d);
    float u = 0.5 + atan(d.x, -d.z) / (2.0 * ENVIRONMENT_PI);
    float v = acos(clamp(d.y, -1.0, 1.0)) / ENVIRONMENT_PI;
    return vec2(u, 1.0 - v);
}

vec3 equirect_direction(vec2 st) {
    float phi = (st.x - 0.5) * 2.0 * ENVIRONMENT_PI;
    float theta = (1.0 - st.y) * ENVIRONMENT_PI;
    return vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
}

vec3 cube_direction(int face, vec2 st) {
    vec2 c = st * 2.0 - 1.0;
    vec3 d;
    if (face == 0) d = vec3(1.0, -c.y, -c.x);
    else if (face == 1) d = vec3(-1.0, -c.y, c.x);
    else if (face == 2) d = vec3(c.x, 1.0, c.y);
    else if (face == 3) d = vec3(c.x, -1.0, -c.y);
    else if (face == 4) d = vec3(c.x, -c.y, 1.0);
    else d = vec3(-c.x, -c.y, -1.0);
    return normalize(d);
}
