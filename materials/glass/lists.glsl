// Per-pixel linked lists of glass fragments (the exact mode): glass_count counts the nodes
// taken, glass_heads[pixel] is the last node a pixel took (GLASS_NONE: none), and node k
// (numbered from 1) holds a layer (materials/glass/layer.glsl) in glass_layers[k - 1]: the
// emitted light and the coverage as half floats and the depth, and in glass_links[k - 1] its
// refraction offset (two halves) and the pixel's node before it. None is 0, what a cleared
// buffer holds and what llvmpipe's loads give the masked-off lanes of the blocks of pixels
// it shades together: with an end marker of another value, a list's loop ran for those lanes
// until its guard, a hundred times the frame's time.
layout(std430, binding = GLASS_HEADS_BINDING) buffer GlassHeads {
    uint glass_count;
    uint glass_heads[];
};
layout(std430, binding = GLASS_LAYERS_BINDING) buffer GlassLayers {
    uvec4 glass_layers[];
};
layout(std430, binding = GLASS_LINKS_BINDING) buffer GlassLinks {
    uvec2 glass_links[];
};

const uint GLASS_NONE = 0u;
uniform int u_glass_width;  // pixels a row of the frame: heads are row after row
