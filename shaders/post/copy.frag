// Copy a target pixel for pixel (deferred.core.passes.copy_pass): the light accumulation into the
// composition buffer (Revie 2.4.4), snapshots a later pass samples while it writes the original.
uniform sampler2D u_source;
out vec4 out_color;

void main() {
    out_color = texelFetch(u_source, ivec2(gl_FragCoord.xy), 0);
}
