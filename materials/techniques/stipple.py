"""Stippled rendering (Revie 2.3.4, Listing 2.6) and stipple obliteration (2.4.4).

A stipple pass writes a mesh into the G-buffer at one pixel in two or four; the lighting phase
lights those samples like any other; a material-phase pass then reads them back and erases them
from the composition buffer. ``STIPPLE_PATTERN`` (2 or 4) selects the pattern in
``techniques/stipple.glsl``.
"""

from __future__ import annotations

from deferred.gbuffer import DEPTH, LINEAR_DEPTH, NORMAL_EXPONENT_ID
from deferred.material import GBufferPass
from deferred.passes import ObjectPass
from deferred.targets import COMPOSITE, LIGHT_ACCUMULATION

PATTERNS = (2, 4)


def pattern_defines(pattern: int) -> dict[str, str]:
    if pattern not in PATTERNS:
        raise ValueError(f"stipple pattern must be one of {PATTERNS}, got {pattern}")
    return {"STIPPLE_PATTERN": str(pattern)}


class StipplePass(GBufferPass):
    """Stipple phase: a mesh into the G-buffer at the pattern's pixels only (fragment shader
    decides, via ``stipple_sample``)."""


class StippleObliterationPass(ObjectPass):
    """Material phase: where this mesh's stipple samples sit in the composition buffer, copy the
    neighbouring pixel's light and depth over them (``techniques/stipple_obliterate.frag``).

    Drawn with the same vertex shader and uniforms as the stipple pass; a pixel is treated as a
    stipple sample only if the G-buffer there holds this material at this fragment's depth.
    """

    fragment = "techniques/stipple_obliterate.frag"
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_test = True
    depth_func = "always"  # the pass writes depth (gl_FragDepth) wherever it keeps a fragment
    extra_reads = (LIGHT_ACCUMULATION, LINEAR_DEPTH, NORMAL_EXPONENT_ID)
