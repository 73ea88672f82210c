"""Selecting one material's or shading model's pixels in a full-screen pass.

A G-buffer pixel's surface id holds the type ids of the material and the shading model that
wrote it (:mod:`deferred.gbuffer.surface_id`). A full-screen pass selects pixels by name, not
by those numbers: :func:`select_surfaces` gives the defines for its program, and the GLSL
``gbuffer/select.glsl`` gives ``bool surface_selected(float surface_id)`` (a surface id as
``gbuffer_fetch`` returns it, or the ``w`` of ``normal_exponent_id``) and
``bool pixel_selected(sampler2D normal_exponent_id, ivec2 pixel)``::

    FullscreenPass("material.pbr_glow", Phase.MATERIAL, "my_effect/glow.frag",
                   {"u_normal_exponent_id": NORMAL_EXPONENT_ID}, (COMPOSITE,), blend="add",
                   defines=select_surfaces(materials=("pbr",)))

    #include "gbuffer/select.glsl"
    ...
    if (!pixel_selected(u_normal_exponent_id, ivec2(gl_FragCoord.xy))) discard;
"""

from __future__ import annotations

from collections.abc import Sequence

from deferred.interfaces import registry


def select_surfaces(materials: Sequence[str] = (), shading_models: Sequence[str] = ()
                    ) -> dict[str, str]:
    """The defines of a program including ``gbuffer/select.glsl`` whose ``surface_selected``
    is true on the pixels of any of ``materials`` or of ``shading_models`` (registered names;
    an unknown one is an ``InputError`` naming the choices)."""
    if isinstance(materials, str) or isinstance(shading_models, str):
        raise TypeError("select_surfaces takes sequences of names: materials=('glass',)")
    if not materials and not shading_models:
        raise ValueError("select_surfaces: name at least one material or shading model")
    defines = {}
    if materials:
        ids = [registry.materials.get(name).type_id for name in materials]
        defines["SELECT_MATERIALS"] = ", ".join(f"{float(i)}" for i in ids)
    if shading_models:
        ids = [registry.shading_models.get(name).type_id for name in shading_models]
        defines["SELECT_SHADING_MODELS"] = ", ".join(f"{i}" for i in ids)
    return defines
