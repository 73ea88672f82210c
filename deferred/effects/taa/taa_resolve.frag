// Temporal anti-aliasing, the resolve (deferred.effects.taa): this frame's jittered composite
// blended with the history reprojected by the motion vectors. The history is first clipped to
// the current 3x3 neighbourhood in YCoCg (its variance box, mean +- gamma sigma, within its
// min/max; or the min/max box alone; a still pixel's min/max), so what the pixel no longer shows (a disocclusion, a
// moving edge, a changed light) cannot linger. Colours are compressed by c / (1 + luma) for
// the clipping and the blend (Karis, "High Quality Temporal Supersampling", 2014), so a bright
// sample does not outweigh its neighbours.
//
// The history holds how many samples it averages (alpha). Where the pixel is still, the blend
// weights them equally up to u_still_samples (a still camera converges to the average over the
// jitter and stipple sequences); where it moves, the current sample keeps at least
// 1 - u_feedback of the weight.
uniform sampler2D u_composite;
uniform sampler2D u_motion;
uniform sampler2D u_history;  // linear RGB, samples averaged (alpha); bilinear filter
uniform bool u_history_valid;
uniform float u_feedback;
uniform int u_still_samples;
uniform int u_clamp;          // 0: variance box within min/max, 1: min/max
uniform float u_variance_gamma;

layout(location = 0) out vec4 out_resolved;  // the frame: linear RGB, the composite's alpha
layout(location = 1) out vec4 out_history;   // the next frame's history

const float STILL = 0.01;  // pixels of motion below which a pixel is still

float luma(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

vec3 compress(vec3 c) {
    return c / (1.0 + luma(c));
}

vec3 expand(vec3 c) {
    return c / max(1.0 - luma(c), 1e-4);
}

vec3 to_ycocg(vec3 c) {
    return vec3(dot(c, vec3(0.25, 0.5, 0.25)), dot(c, vec3(0.5, 0.0, -0.5)),
                dot(c, vec3(-0.25, 0.5, -0.25)));
}

vec3 from_ycocg(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// The history at `uv` through a Catmull-Rom filter in 9 bilinear taps (the 4x4 texels around
// it, the middle two of each row and column merged into one tap): a moving image is resampled
// every frame, and bilinear taps would blur it more each time. At a pixel's centre (no motion)
// it is that texel exactly.
vec4 history_at(vec2 uv) {
    vec2 size = vec2(textureSize(u_history, 0));
    vec2 position = uv * size;
    vec2 centre = floor(position - 0.5) + 0.5;
    vec2 f = position - centre;
    vec2 w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    vec2 w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    vec2 w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    vec2 w3 = f * f * (-0.5 + 0.5 * f);
    vec2 w12 = w1 + w2;
    vec2 t0 = (centre - 1.0) / size;
    vec2 t12 = (centre + w2 / w12) / size;
    vec2 t3 = (centre + 2.0) / size;
    vec4 sum = texture(u_history, vec2(t0.x, t0.y)) * (w0.x * w0.y)
             + texture(u_history, vec2(t12.x, t0.y)) * (w12.x * w0.y)
             + texture(u_history, vec2(t3.x, t0.y)) * (w3.x * w0.y)
             + texture(u_history, vec2(t0.x, t12.y)) * (w0.x * w12.y)
             + texture(u_history, vec2(t12.x, t12.y)) * (w12.x * w12.y)
             + texture(u_history, vec2(t3.x, t12.y)) * (w3.x * w12.y)
             + texture(u_history, vec2(t0.x, t3.y)) * (w0.x * w3.y)
             + texture(u_history, vec2(t12.x, t3.y)) * (w12.x * w3.y)
             + texture(u_history, vec2(t3.x, t3.y)) * (w3.x * w3.y);
    return max(sum, vec4(0.0));
}

// The point where the segment from the box's centre to `history` leaves the box (the
// history itself when inside).
vec3 clip_to_box(vec3 history, vec3 low, vec3 high) {
    vec3 centre = 0.5 * (low + high);
    vec3 half_size = max(0.5 * (high - low), vec3(1e-6));
    vec3 offset = history - centre;
    vec3 units = abs(offset / half_size);
    float most = max(units.x, max(units.y, units.z));
    return most > 1.0 ? centre + offset / most : history;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_composite, 0);
    vec4 centre = texelFetch(u_composite, pixel, 0);
    vec3 current = to_ycocg(compress(max(centre.rgb, vec3(0.0))));
    vec3 sum = vec3(0.0);
    vec3 sum_squares = vec3(0.0);
    vec3 low = current;
    vec3 high = current;
    vec2 motion = vec2(0.0);
    float longest = -1.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1);
            vec3 c = to_ycocg(compress(max(texelFetch(u_composite, q, 0).rgb, vec3(0.0))));
            sum += c;
            sum_squares += c * c;
            low = min(low, c);
            high = max(high, c);
            // the longest motion around: an edge moving over the background takes the
            // object's, so the background does not smear along behind it
            vec2 m = texelFetch(u_motion, q, 0).xy;
            float length_squared = dot(m, m);
            if (length_squared > longest) {
                longest = length_squared;
                motion = m;
            }
        }
    }
    vec2 previous = (gl_FragCoord.xy - motion) / vec2(size);
    bool inside = all(greaterThanEqual(previous, vec2(0.0))) &&
                  all(lessThanEqual(previous, vec2(1.0)));
    if (!u_history_valid || !inside) {
        out_resolved = centre;
        out_history = vec4(max(centre.rgb, vec3(0.0)), 1.0);
        return;
    }
    vec4 stored = history_at(previous);
    vec3 history = to_ycocg(compress(max(stored.rgb, vec3(0.0))));
    bool still = length(motion) < STILL;
    // a still pixel's jittered samples spread over its neighbourhood's min/max, and their
    // average may lie outside the variance box: it is clipped to the min/max alone, which
    // still rejects what the pixel no longer shows
    if (u_clamp == 0 && !still) {
        vec3 mean = sum / 9.0;
        vec3 sigma = sqrt(max(sum_squares / 9.0 - mean * mean, vec3(0.0)));
        low = max(low, mean - u_variance_gamma * sigma);
        high = min(high, mean + u_variance_gamma * sigma);
    }
    vec3 clipped = clip_to_box(history, low, high);
    float most = still ? float(u_still_samples) : 1.0 / max(1.0 - u_feedback, 1e-3);
    float samples = min(stored.a + 1.0, most);
    // a history the clip moved is of something else: it counts as few samples
    if (distance(clipped, history) > 0.02 * (clipped.x + 0.01))
        samples = min(samples, 1.0 / max(1.0 - u_feedback, 1e-3));
    vec3 blended = mix(clipped, current, 1.0 / samples);
    vec3 resolved = expand(from_ycocg(blended));
    out_resolved = vec4(resolved, centre.a);
    out_history = vec4(resolved, samples);
}
