// Concentric shells (Revie 2.3.1, Listing 2.1): a vertex pushed out along its normal bent
// toward the comb direction, by shell_depth (0 base .. 1 outermost) of the fur length.
vec3 shell_offset(vec3 normal, vec3 comb, float shell_depth, float fur_length) {
    vec3 direction = normalize(normal + comb * shell_depth);
    return direction * shell_depth * fur_length;
}
