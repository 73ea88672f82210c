// A deferred fur layer's light moved from its sample to the layer (not in the papers: they take
// a sample's light as it is). A layer fragment reads its light from a sample of the light
// accumulation: its root's pixel (Revie 2.4.4, Listing 2.2; Silva's layers likewise), and for
// revie_fur the stipple sample at the strand's tip. That light was shaded at the sample's
// point, with the sample's surface; the forward layers are shaded where they are. Between the
// two the full-screen lights (ambient, directional) change: a directional light's shadow (a
// strand standing out of the shadow its body casts on its skin: the far side of a ball under a
// side light), the strand's direction (a curl), the view direction (marschner's lobes at a
// silhouette), and with deep opacity maps the transmittance. So the full-screen lights are
// evaluated again at the sample as it was lit (c) and at the layer as the forward layers light
// it (t), and the sample's share of them in the light read is swapped (fur_relit). The volume
// lights (point, spot) keep the sample's light. Include common/light_buffer.glsl and
// generated/lights.glsl first: the light types come from the scene (LIGHT_RANGE_ambient,
// LIGHT_RANGE_environment, LIGHT_RANGE_directional); another full-screen type, a plugin's, is
// in neither c nor t and so keeps the sample's light too.
//
// Each type is a loop over its own range, calling its function: llvmpipe runs every branch of a
// switch on the light type (shadow lookups included) for every light.

uniform int u_global_light_count;  // the full-screen lights, first in the light buffer

// The full-screen lights at P: la for surface a, lb for surface b, b's lit through a's shadow
// lookups (their normal offset: a's normal). A caller with one surface passes it twice; the
// compiler merges the two shadings.
void fur_fullscreen_lights(Surface a, Surface b, vec3 P, vec3 V, out vec3 la, out vec3 lb) {
    la = vec3(0.0);
    lb = vec3(0.0);
#ifdef LIGHT_RANGE_ambient
    if (LIGHT_RANGE_ambient.y > 0) {
        int k = LIGHT_RANGE_ambient.x;
        do {
            LightRecord light = fullscreen_light(k);
            la += ambient_light(light, a, P, V);
            lb += ambient_light(light, b, P, V);
        } while (++k < LIGHT_RANGE_ambient.x + LIGHT_RANGE_ambient.y);
    }
#endif
#ifdef LIGHT_RANGE_environment
    if (LIGHT_RANGE_environment.y > 0) {
        int k = LIGHT_RANGE_environment.x;
        do {
            LightRecord light = fullscreen_light(k);
            la += environment_light(light, a, P, V);
            lb += environment_light(light, b, P, V);
        } while (++k < LIGHT_RANGE_environment.x + LIGHT_RANGE_environment.y);
    }
#endif
#ifdef LIGHT_RANGE_directional
    if (LIGHT_RANGE_directional.y > 0) {
        int k = LIGHT_RANGE_directional.x;
        do {
            vec3 L;
            vec3 radiance = directional_radiance(fullscreen_light(k), P, a.normal, L);
            la += shade_light(a, L, V, radiance);
            lb += shade_light(b, L, V, radiance);
        } while (++k < LIGHT_RANGE_directional.x + LIGHT_RANGE_directional.y);
    }
#endif
}

// The full-screen lights at a layer point P as the forward layers light it (t), for surfaces a
// and b (b through a's shadow lookups). With deep opacity maps (OPACITY_RECEIVER and shadows)
// a shadowed light reaches P through the fur in front of it and gamma(h) darkens the ambient
// and the unshadowed lights, the forward layers' split; gamma is divided out here, since the
// deferred layer multiplies all its light by it.
void fur_layer_lights(Surface a, Surface b, vec3 P, float gamma, out vec3 la, out vec3 lb) {
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    opacity_split = false;
    opacity_fallback = gamma;
    a.occlusion = gamma;
    b.occlusion = gamma;
    fur_fullscreen_lights(a, b, P, normalize(-P), la, lb);
    la /= max(gamma, 1e-3);
    lb /= max(gamma, 1e-3);
#else
    fur_fullscreen_lights(a, b, P, normalize(-P), la, lb);
#endif
}

// The full-screen lights at a sample's point P with its surface s, as the light pass lit it (c):
// a shadowed light by its depth shadow and, where P lies beyond a volume's back, the volume's
// whole transmittance (lighting/shadows.glsl opacity_beyond, the generic passes' lookup).
vec3 fur_sample_light(Surface s, vec3 P) {
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    opacity_split = true;
    opacity_as_light_pass = true;
    opacity_fallback = 1.0;
#endif
    vec3 la, lb;
    fur_fullscreen_lights(s, s, P, normalize(-P), la, lb);
#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)
    opacity_as_light_pass = false;
#endif
    return la;
}

// The light read from a sample (irradiance) with the full-screen lights' share swapped, per
// channel: c, those lights at the sample as it was lit, for t, at the layer. Where c lies
// within what was read, read - c + t (t alone without volume lights); where the sample read
// less (its ambient occlusion, or a neighbour's pixel in a shadow c does not see), the read
// light scaled by t / c. Never negative, continuous where read = c.
vec3 fur_relit(vec3 read, vec3 c, vec3 t) {
    // with no volume light in the frame all the light read is the full-screen lights': what it
    // holds beyond c is the sample's pixel showing another point than c's (a neighbour's, at a
    // silhouette), not light
    vec3 rest = u_light_count > u_global_light_count ? read - c : vec3(0.0);
    return mix(read * t / max(c, vec3(1e-6)), rest + t, step(c, read));
}

#if defined(SHADOWS) && defined(OPACITY_SHADOWS) && defined(OPACITY_RECEIVER)

// Self-shadowing from the volume lights (deep opacity maps, lighting/shadows.glsl): the light
// read from a sample holds each shadowed volume light whole (the full-screen ones are t's,
// relit with their transmittance). Each is evaluated again at the layer for surface s (e_i) and
// its share of the light scaled by its transmittance there: f = sum(e_i T_i / gamma) / sum(e_i)
// (gamma(h) stays on the rest, as in the forward layers; the caller multiplies by it), over
// the share sum(e_i) / irradiance, at most what the full-screen lights' `fullscreen` leave of
// it: where the layer sees more of a light than its sample did, past the sample's terminator,
// the ambient in its light is kept and the fur there turns no black.
vec3 fur_volume_self_shadowed(vec3 irradiance, vec3 fullscreen, Surface s, vec3 P, vec3 V,
                              float gamma) {
    const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);
    vec3 inverse_albedo = 1.0 / max(s.albedo, vec3(1.0 / 255.0));
    float total = 0.0;
    float kept = 0.0;
    opacity_split = true;
    opacity_fallback = 1.0;
    for (int k = u_global_light_count; k < u_light_count; ++k) {
        LightRecord light = fetch_light(k);
        if (light.extra.w < 0.5) continue;  // no shadow slot: gamma(h) stays
        opacity_last = 1.0;
        float e = dot(evaluate_volume_light(light, s, P, V) * inverse_albedo, LUMA);
        total += e;
        kept += e * opacity_last / max(gamma, 1e-3);
    }
    float read = max(dot(irradiance, LUMA), 1e-6);
    float share = clamp(total / read, 0.0, max(1.0 - dot(fullscreen, LUMA) / read, 0.0));
    return irradiance * mix(1.0, kept / max(total, 1e-6), share);
}
#endif
