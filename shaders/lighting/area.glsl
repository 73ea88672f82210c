// Area lights by linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt 2016;
// deferred.interfaces.area). An area light's GLSL fills an AreaLight (its polygon's corners
// relative to the shaded point, in order around it, and the radiance arriving: the emitted
// radiance times its window and shadow) and calls shade_area, which the surface's shading model
// answers (its area function, or the light as a point light: area_as_point_light).
//
// The integrals here are of the clamped cosine over the polygon clipped to the upper hemisphere
// of a frame: area_cosine_integral(a, to_frame) = the integral of max(z, 0) over the polygon
// after to_frame (a rotation into the surface's frame, or an LTC's inverse matrix times it),
// from the edges' angles (Stokes: (1/2) sum of theta_i times the unit normal of edge i's plane).
// In the surface's frame it is the irradiance per unit radiance; over pi after an LTC's matrix
// it is the lobe's share of the light, which the lobe's magnitude turns into reflectance.
#include "common/lighting.glsl"

#define AREA_LIGHT_CORNERS 12
struct AreaLight {
    vec3 corners[AREA_LIGHT_CORNERS];  // view space, relative to the shaded point
    int count;                         // corners used (3 .. AREA_LIGHT_CORNERS)
    vec3 radiance;                     // the emitted radiance reaching the point
};

// Heitz et al.'s GGX fit (shaders/lighting/ltc_ggx.npz): over (roughness, sqrt(1 - N.V)),
// the inverse matrix's free entries (m00, m02, m20, m22; m11 = 1) and the lobe's magnitude
// and Fresnel-weighted part (x, y)
uniform sampler2D u_ltc_matrix;
uniform sampler2D u_ltc_amplitude;
const float AREA_PI = 3.14159265358979;
const float LTC_TABLE_SIZE = 64.0;

// 1 near the light, 0 at its range (the sphere the light paths bound it by) and behind its
// plane (a one-sided emitter); centre is the light's centre relative to the point
float area_light_window(LightRecord light, vec3 centre) {
    if (dot(centre, light.direction.xyz) >= 0.0) return 0.0;
    float ratio = length(centre) / light.position.w;
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    return window * window;
}

// theta times the unit normal of the plane through 0, a and b (unit vectors): the edge's part
// of the polygon's vector irradiance, twice over
vec3 area_edge(vec3 a, vec3 b) {
    vec3 c = cross(a, b);
    float s = length(c);
    return s > 1e-9 ? c * (atan(s, dot(a, b)) / s) : vec3(0.0);
}

// The integral of max(z, 0) over the polygon seen through to_frame (the module comment):
// Sutherland-Hodgman clipping at z = 0, the clipped polygon's edges summed as they come.
float area_cosine_integral(AreaLight a, mat3 to_frame) {
    float sum = 0.0;
    vec3 first = vec3(0.0), last = vec3(0.0);
    int emitted = 0;
    vec3 p = to_frame * a.corners[a.count - 1];
    for (int k = 0; k < a.count; ++k) {
        vec3 q = to_frame * a.corners[k];
        bool p_in = p.z > 0.0, q_in = q.z > 0.0;
        for (int e = 0; e < 2; ++e) {  // at most two points an edge: a crossing, its end
            vec3 point;
            if (e == 0) {
                if (p_in == q_in) continue;
                point = p + (q - p) * (p.z / (p.z - q.z));
                point.z = 0.0;
            } else {
                if (!q_in) continue;
                point = q;
            }
            point = normalize(point);
            if (emitted == 0) first = point;
            else sum += area_edge(last, point).z;
            last = point;
            ++emitted;
        }
        p = q;
    }
    if (emitted >= 3) sum += area_edge(last, first).z;
    return 0.5 * abs(sum);
}

// The vector irradiance of the whole polygon, unclipped, toward it: its dot with a unit normal
// is the irradiance per unit radiance of a surface facing all of it
vec3 area_vector_irradiance(AreaLight a) {
    vec3 sum = vec3(0.0);
    vec3 middle = vec3(0.0);
    vec3 p = normalize(a.corners[a.count - 1]);
    for (int k = 0; k < a.count; ++k) {
        vec3 q = normalize(a.corners[k]);
        sum += area_edge(p, q);
        middle += a.corners[k];
        p = q;
    }
    sum *= 0.5;
    return dot(sum, middle) < 0.0 ? -sum : sum;
}

// Rows T1, T2, N: view space into the frame of normal N with V in the x-z plane (the LTC
// tables' frame)
mat3 area_surface_frame(vec3 N, vec3 V) {
    vec3 T1 = V - N * dot(V, N);
    float len = length(T1);
    T1 = len > 1e-5 ? T1 / len : normalize(cross(N, abs(N.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0)));
    return transpose(mat3(T1, cross(N, T1), N));
}

// The irradiance at a surface of normal N per unit radiance: the clipped cosine integral
float area_irradiance(AreaLight a, vec3 N) {
    return area_cosine_integral(a, area_surface_frame(N, vec3(0.0, 0.0, 1.0)));
}

vec2 ltc_uv(float roughness, float n_dot_v) {
    vec2 uv = vec2(clamp(roughness, 0.0, 1.0), sqrt(clamp(1.0 - n_dot_v, 0.0, 1.0)));
    return uv * ((LTC_TABLE_SIZE - 1.0) / LTC_TABLE_SIZE) + 0.5 / LTC_TABLE_SIZE;
}

// The GGX lobe of roughness (alpha = roughness^2) at the point, integrated over the polygon:
// the lobe's share of the light (the LTC's cosine integral over pi), and in .yz the lobe's
// magnitude and Fresnel-weighted part at this N.V: f0 * y + (1 - f0) * z is its reflectance
vec3 area_ggx(AreaLight a, vec3 N, vec3 V, float roughness) {
    vec2 uv = ltc_uv(roughness, clamp(dot(N, V), 0.0, 1.0));
    vec4 m = texture(u_ltc_matrix, uv);
    mat3 inverse_lobe = mat3(vec3(m.x, 0.0, m.y), vec3(0.0, 1.0, 0.0), vec3(m.z, 0.0, m.w));
    float share = area_cosine_integral(a, inverse_lobe * area_surface_frame(N, V)) / AREA_PI;
    return vec3(share, texture(u_ltc_amplitude, uv).xy);
}

// A shading model without an area function: the light as a point light in the direction of
// its vector irradiance, bringing that much irradiance (exact for a Lambertian surface facing
// all of the light; a point light's answer as the light shrinks)
vec3 area_as_point_light(Surface s, vec3 V, AreaLight a) {
    vec3 J = area_vector_irradiance(a);
    float size = length(J);
    if (size <= 0.0) return vec3(0.0);
    return shade_light(s, J / size, V, a.radiance * size);
}

// The surface's shading model answers an area light (generated dispatch, deferred.interfaces.shading)
vec3 shade_area(Surface s, vec3 V, AreaLight a);
