"""Light paths: how lights reach the pixels (Olsson and Assarsson 2011, "Tiled Shading";
Olsson, Billeter and Assarsson 2012, "Clustered Deferred and Forward Shading").

Deferred:

- ``volumes``: one instanced pass per light type, each light drawn as its bounding sphere (or a
  full-screen triangle), re-reading the G-buffer and blending into the light accumulation for
  every pixel it covers. Needs GL 3.3 only.
- ``tiled``: a compute pass culls the volume lights per 16x16 tile against the tile's frustum,
  depth bounds and the view-space box of its points (``lighting/cull_tiles.comp``), in two
  dispatches: coarse tiles of 4x4 tiles against every light, then each tile against its
  coarse tile's lights, and the lights that touch the tile against each of its 8x8 quadrants,
  which have the lists; one full-screen pass then reads the G-buffer once per pixel and loops
  the full-screen lights and its quadrant's list (``lighting/list_shading.frag``).
- ``clustered``: the same shading, from lists of view-space clusters (32x32 tiles x 16
  exponential depth slices) filled tile by tile (``lighting/cull_clusters.comp``).

Forward:

- ``naive``: every fragment loops every light.
- ``tiled`` (Forward+): a depth pre-pass, the tiled culling (depth bounds from the near plane, so
  blended surfaces in front of the opaque ones are covered), and the lit passes loop their
  quadrant's list (``common/forward_lighting.glsl``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from deferred.errors import InputError
from deferred.names import EQUIVALENT_PATHS, LIST_PATHS, LightPath, Pipeline

if TYPE_CHECKING:
    from deferred.gl.context import Features

def resolve_light_path(pipeline: str, requested: str | None, features: Features,
                       where: str = "light_path") -> str:
    """The light path a pipeline runs: ``requested`` (either pipeline's name of it), or the
    fastest this context allows (tiled when compute shaders exist; volumes and naive on GL 3.3,
    where they are the only ones)."""
    if requested is None:
        return LightPath.TILED if features.compute_shaders else \
            (LightPath.VOLUMES if pipeline == Pipeline.DEFERRED else LightPath.NAIVE)
    if requested not in set(LightPath):
        raise InputError(f"unknown light path '{requested}' (choose from "
                         f"{', '.join(LightPath)})", where)
    requested = LightPath(requested)
    path = EQUIVALENT_PATHS[Pipeline(pipeline)].get(requested, requested)
    if path in LIST_PATHS and not features.compute_shaders:
        raise InputError(f"light path '{requested}' needs compute shaders (GL 4.3); this context "
                         "has the GL 3.3 paths only (volumes, naive)", where)
    return path
