// Start of the lighting phase: light accumulation is 0 on surfaces and the scene background
// where the G-buffer holds none (surface id 0), so later phases can sample any pixel.
// Alpha is coverage: 1 on surfaces, 0 on the background.
uniform sampler2D u_normal_exponent_id;
uniform vec3 u_background;

out vec4 out_light;

void main() {
    float surface_id = texelFetch(u_normal_exponent_id, ivec2(gl_FragCoord.xy), 0).w;
    out_light = surface_id > 0.0 ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(u_background, 0.0);
}
