// Blinn-Phong from one directional light and every point light, looped per fragment, with a
// windowed inverse-square falloff (what a hand-written forward renderer does).
#version 330
#define MAX_LIGHTS 128
uniform vec3 u_eye;
uniform vec3 u_color;
uniform vec3 u_sun_direction;   // towards the light
uniform vec3 u_sun_color;
uniform vec3 u_ambient;
uniform int u_count;
uniform vec4 u_lights[MAX_LIGHTS * 2];  // (position, radius), (colour, 0)
in vec3 v_world;
in vec3 v_normal;
out vec4 out_color;

vec3 blinn_phong(vec3 N, vec3 V, vec3 L, vec3 radiance) {
    vec3 H = normalize(L + V);
    float diffuse = max(dot(N, L), 0.0);
    float specular = diffuse > 0.0 ? pow(max(dot(N, H), 0.0), 32.0) * 0.3 : 0.0;
    return radiance * (u_color * diffuse + vec3(specular));
}

void main() {
    vec3 N = normalize(v_normal);
    vec3 V = normalize(u_eye - v_world);
    vec3 total = u_ambient * u_color + blinn_phong(N, V, u_sun_direction, u_sun_color);
    for (int i = 0; i < u_count; ++i) {
        vec4 sphere = u_lights[2 * i];
        vec3 to_light = sphere.xyz - v_world;
        float d2 = dot(to_light, to_light);
        float ratio = d2 / (sphere.w * sphere.w);
        if (ratio >= 1.0) continue;
        float window = (1.0 - ratio * ratio);
        float falloff = window * window / (d2 + 1.0);
        total += blinn_phong(N, V, to_light * inversesqrt(d2), u_lights[2 * i + 1].rgb * falloff);
    }
    out_color = vec4(total / (total + 1.0), 1.0);
}
