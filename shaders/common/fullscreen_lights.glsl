// The full-screen lights' records (ambient, directional) as a uniform array, four vec4s a light,
// in the light buffer's order (deferred.lighting.buffer): the light loops of the list paths and of
// forward read them at every pixel, and llvmpipe reads a uniform faster than a texel.
// FULLSCREEN_LIGHT_CAPACITY comes from deferred.lighting.dispatch (the generated light dispatch).
uniform vec4 u_fullscreen_lights[4 * FULLSCREEN_LIGHT_CAPACITY];

LightRecord fullscreen_light(int index) {
    return LightRecord(u_fullscreen_lights[4 * index], u_fullscreen_lights[4 * index + 1],
                       u_fullscreen_lights[4 * index + 2], u_fullscreen_lights[4 * index + 3],
                       index);
}
