// Copy a target pixel for pixel (light accumulation into the composition buffer, Revie 2.4.4).
uniform sampler2D u_source;
out vec4 out_color;

void main() {
    out_color = texelFetch(u_source, ivec2(gl_FragCoord.xy), 0);
}
