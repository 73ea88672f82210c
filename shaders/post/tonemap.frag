// Post: exposure, tone mapping and sRGB encoding of the composition buffer.
#include "common/color.glsl"

uniform sampler2D u_source;
uniform float u_exposure;
// TONEMAP (deferred.render.pipeline.TONEMAPS): 0 none (clamp), 1 Reinhard, 2 ACES (Narkowicz 2015
// fit). A define, not a uniform: on llvmpipe an `if` runs both operators (8% of the pass).
#ifndef TONEMAP
#define TONEMAP 2  // the scenes' default
#endif

layout(location = 0) out vec4 out_color;
#ifdef WRITE_SNAPSHOT
// a copy of the final image a later post pass reads while it writes the final image (FXAA's)
layout(location = 1) out vec4 out_snapshot;
#endif

vec3 aces_fit(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main() {
    vec3 color = max(texelFetch(u_source, ivec2(gl_FragCoord.xy), 0).rgb, 0.0) * u_exposure;
#if TONEMAP == 1
    color = color / (1.0 + color);
#elif TONEMAP == 2
    color = aces_fit(color);
#endif
    out_color = vec4(srgb_encode(color), 1.0);
#ifdef WRITE_SNAPSHOT
    out_snapshot = out_color;
#endif
}
