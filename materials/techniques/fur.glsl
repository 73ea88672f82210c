// The fur technique's volume lookups (materials/techniques/fur.py, fur_volume.py): coverage and
// brightness of the strands at height h (0 root .. 1 tip) of the fur layer.
//
// Mapping: triplanar, in world units. Strands are looked up at the base-mesh point under the
// fragment (object space scaled to world size, times the tiles per unit that `density` gives),
// in one of the three axis planes, chosen per cell with the object-space normal's weights as
// the odds, blended at the cells' borders (fur_sample_grad). It has no UV seams and no poles,
// and the density is the same on every part of every mesh whatever its unwrap.

#define FUR_SUBSLICES 4.0  // fur_volume.py's SUBSLICES
uniform sampler2DArray u_fur_volume;  // slices of the strand volume, mip-mapped (alpha = coverage)
uniform float u_fur_tiles;            // volume tiles per world unit
uniform float u_self_shadow;          // Silva's K_shadow >= 1: fur darkens toward the roots
uniform float u_self_shadow_density;  // k: the deep opacity maps hold k x optical depth

// Coverage (x) and brightness * coverage (y) of the volume at height h: the generated slices
// around h, interpolated. The texture holds SUBSLICES interpolated slices per interval between
// two generated ones (fur_volume.py): one lookup, of the nearest, at h rounded to a quarter of
// the slice spacing.
vec2 fur_slices(vec2 coord, vec2 dx, vec2 dy, float h) {
    float slices = float(textureSize(u_fur_volume, 0).z);
    float layers = (slices - 1.0) / FUR_SUBSLICES + 1.0;  // generated slices
    float x = clamp(h * layers - 0.5, 0.0, layers - 1.0);
    vec4 s = textureGrad(u_fur_volume, vec3(coord, x * FUR_SUBSLICES), dx, dy);  // layer rounds
    return vec2(s.a, s.r);
}

// (coverage, brightness * coverage) at the fur position (world units, object axes) and
// object-space normal of a base-mesh point, at height h, with the screen gradients of the fur
// position (they choose the mip level).
//
// Triplanar by selection, not by mixing: where the planes' weights overlap, each cell of a
// volume tile shows the strands of one plane, chosen by a hash of the cell with the weights as
// the odds. Mixing the planes' coverages everywhere would lay two sparser patterns of strands
// over each other: more pixels half covered, the darker roots hidden, and coarse fur brighter
// in the blend zones than on an axis. A cell's choice is the same for every shell (the base
// point decides), so strands stay whole inside it.
//
// At a border between cells that chose different planes the choice is blended over a narrow
// band (FUR_SELECT_BAND of a cell each side), as is the choice within a cell where the weights
// cross its hash (FUR_SELECT_SOFT): a hard switch cut the strands straddling it along a
// straight line, which curled fur, each layer shifted along its helix, showed as a crack (the
// border x = 0 down the front of Fig. 7 (d)'s ball). The bands are a small part of the
// surface, so the mixing's brightening there stays small.
#define FUR_SELECT_CELLS 1.0  // selection cells per volume tile (more cut more strands)
#define FUR_SELECT_BAND 0.06  // blend band each side of a cell border, in cells
#define FUR_SELECT_SOFT 0.03  // blend band of the weights around a cell's hash

float fur_cell_hash(vec3 cell) {
    return fract(sin(dot(cell, vec3(12.9898, 78.233, 37.719))) * 43758.5453);
}

// A cell's choice as weights of the x, y and z planes: one-hot but within FUR_SELECT_SOFT of
// where the cumulative weights cross the cell's hash.
vec3 fur_cell_choice(vec3 cell, vec3 w) {
    float pick = fur_cell_hash(cell);
    float x = clamp((w.x - pick) / (2.0 * FUR_SELECT_SOFT) + 0.5, 0.0, 1.0);
    float xy = clamp((w.x + w.y - pick) / (2.0 * FUR_SELECT_SOFT) + 0.5, 0.0, 1.0);
    return vec3(x, xy - x, 1.0 - xy);
}

vec2 fur_sample_grad(vec3 fur_position, vec3 fur_normal, float h, vec3 dx, vec3 dy) {
    vec3 p = fur_position * u_fur_tiles;
    vec3 px = dx * u_fur_tiles;
    vec3 py = dy * u_fur_tiles;
    vec3 w = pow(abs(fur_normal), vec3(8.0));
    w /= max(w.x + w.y + w.z, 1e-6);
    // the choices of the (up to 8) cells around p, weighted trilinearly between cell centres
    // with the ramp squeezed into the bands at the borders
    vec3 q = p * FUR_SELECT_CELLS - 0.5;
    vec3 base = floor(q);
    vec3 t = smoothstep(0.5 - FUR_SELECT_BAND, 0.5 + FUR_SELECT_BAND, q - base);
    vec3 planes = vec3(0.0);
    for (int k = 0; k < 8; ++k) {
        vec3 corner = vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        vec3 f = mix(1.0 - t, t, corner);
        float weight = f.x * f.y * f.z;
        if (weight > 0.0) planes += weight * fur_cell_choice(base + corner, w);
    }
    vec2 strands = vec2(0.0);
    if (planes.x > 1e-3) strands += planes.x * fur_slices(p.yz, px.yz, py.yz, h);
    if (planes.y > 1e-3) strands += planes.y * fur_slices(p.zx, px.zx, py.zx, h);
    if (planes.z > 1e-3) strands += planes.z * fur_slices(p.xy, px.xy, py.xy, h);
    return strands / max(planes.x * float(planes.x > 1e-3) + planes.y * float(planes.y > 1e-3)
                         + planes.z * float(planes.z > 1e-3), 1e-6);
}

// Over the mesh's UVs instead (Silva et al. section 4: the fur texture at (u, v, h)): one lookup
// pair instead of three, the density following the unwrap; `tiles` volume tiles per UV unit,
// dx and dy the screen gradients of uv.
vec2 fur_sample_uv(vec2 uv, float h, float tiles, vec2 dx, vec2 dy) {
    return fur_slices(uv * tiles, dx * tiles, dy * tiles, h);
}

#ifndef FUR_NO_DERIVATIVES  // a vertex shader (tests/fixtures/fur_selection_harness)
// The same with the gradients of fur_position itself. Derivatives in uniform control flow; the
// branches above only skip negligible planes.
vec2 fur_sample(vec3 fur_position, vec3 fur_normal, float h) {
    return fur_sample_grad(fur_position, fur_normal, h, dFdx(fur_position), dFdy(fur_position));
}
#endif

// The strands' own brightness where they cover (the volume's, 0.7 .. 1 a strand, seeded); the
// skin between them, on the root shell, is 1.
float strand_brightness(vec2 strands) {
    return mix(1.0, strands.y / max(strands.x, 1e-4), min(strands.x, 1.0));
}

// Each strand's own tint (not in the papers): its brightness also saturates a darker strand's
// colour and pales a lighter one's, albedo^(1 + 1.2 (0.85 - brightness)) where strands cover,
// so neighbouring strands differ in hue, not only in value.
vec3 strand_tint(vec3 albedo, vec2 strands) {
    float shift = 1.2 * (0.85 - strand_brightness(strands)) * min(strands.x, 1.0);
    return pow(max(albedo, vec3(0.0)), vec3(1.0 + shift));
}

// A shell's opacity from the volume's coverage: each shell stands for 1/n of the layer, so with
// n shells coverage c becomes 1 - (1 - c)^(slices / n) (`weight`): the fur's optical depth, and
// so its colour, stays the same whatever the level of detail draws.
float shell_opacity(float coverage, float weight) {
    return 1.0 - pow(max(1.0 - coverage, 0.0), weight);
}

// Silva et al.'s shadow factor gamma = (K - 1 + h) / K: self-shadowing of the lower fur.
float fur_shadow(float h) {
    return (u_self_shadow - 1.0 + h) / u_self_shadow;
}
