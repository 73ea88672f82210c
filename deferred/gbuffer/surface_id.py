"""The surface id: which material and shading model wrote a G-buffer pixel.

The G-buffer's id channel (a half float) holds ``shading model * MATERIAL_IDS + material id``,
both registry type ids (0 = background). Integers up to 2048 are exact in a half, so 63
materials and 31 shading models fit. The GLSL reading it gets the same constant
(:func:`surface_id_glsl`, included by ``common/surface.glsl``).
"""

from __future__ import annotations

SURFACE_ID_FILE = "generated/surface_id.glsl"

MATERIAL_IDS = 64
MAX_MATERIAL_ID = MATERIAL_IDS - 1
MAX_SHADING_MODEL_ID = 2047 // MATERIAL_IDS


def surface_id(material_id: int, shading_model_id: int) -> int:
    """The value an object writes to the G-buffer's id channel (``common/surface.glsl``)."""
    if not 0 < material_id <= MAX_MATERIAL_ID or not 0 < shading_model_id <= MAX_SHADING_MODEL_ID:
        raise ValueError(f"ids out of range: material {material_id}, shading model "
                         f"{shading_model_id}")
    return shading_model_id * MATERIAL_IDS + material_id


def split_surface_id(value):
    """(material id, shading model id) of G-buffer id values (numpy arrays or numbers)."""
    return value % MATERIAL_IDS, value // MATERIAL_IDS


def surface_id_glsl() -> str:
    """``MATERIAL_IDS`` for the GLSL that packs and splits surface ids."""
    return f"const float MATERIAL_IDS = {float(MATERIAL_IDS)};\n"
