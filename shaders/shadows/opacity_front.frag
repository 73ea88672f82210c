// The fronts of a tile of the deep opacity maps grown by a texel (deferred.lighting.shadows,
// ShadowPass._opacity): a texel where no volume was drawn takes the nearest front and the
// farthest back of its 3x3 neighbours in the tile. A front is drawn where a texel's centre lies
// inside the volume as the light sees it; where the light grazes the volume, one texel
// stretches along its surface, and a point there whose texel's centre missed the volume,
// though deep in it, would see nothing in front and stay lit beside points in shadow. With a
// neighbour's front, the layers (filtered linearly, nothing drawn in this texel) fade out over
// the edge instead.
uniform sampler2D u_opacity_drawn;  // RG32F: the fronts and minus the backs as drawn (3e38: none)
uniform ivec4 u_tile;               // the tile's first and last texels (x0, y0, x1, y1)

out vec4 out_value;

void main() {
    ivec2 centre = ivec2(gl_FragCoord.xy);
    vec2 drawn = texelFetch(u_opacity_drawn, centre, 0).rg;
    if (drawn.x > 1.0e37) {
        for (int y = -1; y <= 1; ++y) {
            for (int x = -1; x <= 1; ++x) {
                ivec2 texel = clamp(centre + ivec2(x, y), u_tile.xy, u_tile.zw);
                drawn = min(drawn, texelFetch(u_opacity_drawn, texel, 0).rg);
            }
        }
    }
    out_value = vec4(drawn, 0.0, 0.0);
}
