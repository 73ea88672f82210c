"""cartoon_hair's passes beyond the head's surface: the tubes (a second surface of the object,
:data:`TUBES` as their input and shape), their hatching (4.3.8) and their silhouette strokes
(4.3.7), each reading the hair at the frame's time."""

from __future__ import annotations

from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from deferred.api import (
    COMPOSITE,
    DEPTH,
    InputError,
    MeshPrimitives,
    ObjectPass,
    Order,
    PassInput,
    Phase,
    RenderPass,
    Technique,
)

from ..techniques.hair_silhouettes import SilhouetteEdges, SilhouettePass
from ..techniques.hair_tubes import tube_radii
from ..techniques.hatching import TamSettings, tam_texture, tonal_art_map
from .params import MAX_HAIR_OBJECTS, STRAND_IDS
from .state import DYNAMICS

if TYPE_CHECKING:
    import moderngl

    from deferred.api import Frame, Material, SceneObject

def strand_base(scene, obj: SceneObject) -> float:
    """The first strand id of ``obj``'s hair: each cartoon_hair object of the scene has its own
    range of ``STRAND_IDS`` ids, so strands of two heads are told apart too."""
    hairs = [other for other in scene.objects if other.material.simulation is DYNAMICS]
    index = next((k for k, other in enumerate(hairs) if other.node is obj.node), 0)
    if index >= MAX_HAIR_OBJECTS:
        raise InputError(f"a scene holds at most {MAX_HAIR_OBJECTS} cartoon_hair objects (their "
                         "strand ids share one float channel)", obj.label)
    return float(index * STRAND_IDS)


class HairTubes(PassInput):
    """The hair's tubes as a pass's input and shape: the pass draws the tubes instead of the
    object's mesh (the head), in the hair's ``color``, with its strands' ids."""

    def uniforms(self, frame: Frame, obj: SceneObject) -> dict[str, Any]:
        params = obj.params
        return {"u_hair": True, "u_color": params.color,
                "u_specular_intensity": params.specular_intensity,
                "u_specular_exponent": params.specular_exponent,
                "u_strand_base": strand_base(frame.scene, obj)}

    def draw(self, frame: Frame, obj: SceneObject, program: moderngl.Program) -> None:
        DYNAMICS.state(frame, obj).gpu.render(program)


TUBES = HairTubes()


class HatchingPass(ObjectPass):
    """The tubes again, their lit tone's hatching multiplied over the lit hair (4.3.8): the
    lighting evaluated here (every light of the frame, as the forward pipeline does), the ink
    from the tonal art map (:mod:`.techniques.hatching`, made once and cached on disk)."""

    fragment = "materials/cartoon_hair/hatching.frag"
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_func = "lequal"
    depth_write = False
    blend = "multiply"
    order = Order.OPAQUE  # the material's own pixels, before its strokes

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        params = self.object(frame).params
        tam = hatching_map(params.hatching_width)
        means = np.zeros(MAX_TAM_TONES)
        means[:tam.tones] = tam.ink(tam.mips - 1).mean(axis=(1, 2))
        return {"u_tam_tones": tam.tones, "u_tam_gutter": tam.gutter, "u_tam_mips": tam.mips,
                "u_tam_mean": tuple(float(m) for m in means),
                "u_hatching_strength": params.hatching_strength,
                "u_hatching_scale": params.hatching_scale,
                "u_hatching_screen": params.hatching == "screen"}

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        width = self.object(frame).params.hatching_width
        texture = frame.resources.cached(("cartoon_hair_tam", width),
                                         lambda ctx: tam_texture(ctx, hatching_map(width)))
        return {"u_tam": texture}


MAX_TAM_TONES = 64  # hatching.glsl's u_tam_mean


@lru_cache(maxsize=8)
def hatching_map(width: float):
    """The hatching's tonal art map for strokes ``width`` pixels wide (4.3.8 as pen strokes):
    the thesis' 6 tones, at 256^2 with 4 levels (strokes still cover several pixels at the
    coarsest, 32^2), strokes 0.3 of the tile long along the strand (hair is hatched along its
    grain, not crossed), enough of them that the darkest tone is about half ink (cached on disk
    by :func:`.techniques.hatching.tonal_art_map`)."""
    strokes = int(round(TAM_INK_STROKES / width))
    return tonal_art_map(TamSettings(size=256, tones=6, mips=4, strokes=strokes, candidates=10,
                                     stroke_length=0.3, stroke_width=float(width)))


TAM_INK_STROKES = 900.0  # strokes times their width (pixels): the darkest tone's ink


class HairSilhouettePass(SilhouettePass):
    """The tubes' silhouette strokes over the lit image."""

    def silhouette_geometry(self, frame: Frame) -> MeshPrimitives:
        return DYNAMICS.state(frame, self.object(frame)).silhouettes

    def silhouette_edges(self, frame: Frame) -> SilhouetteEdges:
        return DYNAMICS.state(frame, self.object(frame)).silhouette_edges

    def tube_vertices(self, frame: Frame) -> moderngl.Buffer:
        return DYNAMICS.state(frame, self.object(frame)).gpu.surface_vbo

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        uniforms = super().uniforms(frame)
        if self.id_buffer:  # the stroke's own strand's id in the G-buffer
            uniforms["u_strand_base"] = strand_base(frame.scene, self.object(frame))
        return uniforms

    def stroke_settings(self, frame: Frame) -> dict[str, Any]:
        p = self.object(frame).params
        # a tube's own front surface lies up to its radius nearer than its silhouette
        return {"width": p.stroke_width, "world_width": p.stroke_world_width,
                "color": p.stroke_color, "fade": p.stroke_fade, "radius": p.radius,
                "taper": p.taper,
                "tolerance": float(tube_radii(p.hair_samples, p.radius, p.taper).max())}


class HairStrokes(Technique):
    """The tubes' hatching (where ``hatching`` is not "none") and silhouette strokes (with
    ``silhouettes``): over the lit image in the material phase, and after the lit hair in the
    forward pipeline (the hatching blended after the opaque lit passes)."""

    def passes(self, material: Material, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        params = material.params
        if phase not in (Phase.MATERIAL, Phase.FORWARD):
            return []
        forward = phase == Phase.FORWARD
        prefix = "forward_" if forward else ""
        passes: list[RenderPass] = []
        if params.hatching != "none":
            options = {"order": Order.VOLUME} if forward else {}
            passes.append(HatchingPass(f"{obj.label}.{prefix}hatching", phase, obj,
                                       inputs=(TUBES,), shape=TUBES, **options))
        if params.silhouettes:
            options = {} if forward else {"id_buffer": True}
            passes.append(HairSilhouettePass(f"{obj.label}.{prefix}silhouettes", phase, obj,
                                             **options))
        return passes
