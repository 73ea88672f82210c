// Vignette: a factor that falls from 1 at `radius` to 1 - strength in the corners; the pass
// blends it multiplicatively over the final frame.
uniform vec2 u_resolution;
uniform float u_strength;
uniform float u_radius;

out vec4 out_color;

void main() {
    vec2 centred = gl_FragCoord.xy / u_resolution - 0.5;
    float distance = length(centred) * 1.41421356;  // 1 in the corners
    float factor = 1.0 - u_strength * smoothstep(u_radius, 1.0, distance);
    out_color = vec4(vec3(factor), 1.0);
}
