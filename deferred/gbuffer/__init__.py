"""The G-buffer: its layout (core targets, the data materials declare, the GLSL that writes and
reads them) and the surface-id encoding of its id channel."""

from deferred.gbuffer.layout import (
    ALBEDO_SPECULAR,
    DEPTH,
    GBUFFER_COLOR_TARGETS,
    GBUFFER_TARGETS,
    LINEAR_DEPTH,
    MOTION,
    MOTION_SPEC,
    NORMAL_EXPONENT_ID,
    GBufferData,
    GBufferLayout,
    decode,
    octahedral_decode,
    octahedral_encode,
)
from deferred.gbuffer.surface_id import MATERIAL_IDS, split_surface_id, surface_id

__all__ = ["ALBEDO_SPECULAR", "DEPTH", "GBUFFER_COLOR_TARGETS", "GBUFFER_TARGETS",
           "LINEAR_DEPTH", "MATERIAL_IDS", "MOTION", "MOTION_SPEC", "NORMAL_EXPONENT_ID",
           "GBufferData", "GBufferLayout",
           "decode", "octahedral_decode", "octahedral_encode", "split_surface_id", "surface_id"]
