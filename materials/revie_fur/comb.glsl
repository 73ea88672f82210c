// The comb parameters the fragment stages read (included once, by the surface and the shells).
uniform float u_comb_strength;
