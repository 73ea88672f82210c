"""Cartoon hair (Costigan, "Cartoon Hair Simulation", chapters 3-4): guide strands on the
object's scalp, simulated as mass-spring chains, swept into tapered tube meshes every frame and
shaded by the ``toon`` model through the material's X-toon ramp; the object's own mesh (the
head) is drawn too, in ``skin_color``.

- strands (4.1-4.2.1): from ``strands_file`` (JSON or OBJ polylines, object space) or grown on
  the scalp (the mesh's vertex-colour alpha: ``builtin:head`` paints one) in a ``style``;
- dynamics (4.2.2-4.2.4): :mod:`.techniques.hair_dynamics`, the roots pinned to the object,
  colliding with ``collision_spheres`` (``builtin:head``'s own by default), anchored to
  ``keyframes`` (strand files at ``key_times``, Catmull-Rom in time) by ``anchor_stiffness``;
  stepped from t = 0 at ``time_step`` (after ``settle`` seconds at rest before it), each step
  with the parameters of the scene's timeline at its time (gravity, wind, drag, stiffnesses,
  anchors, and every shading parameter may change between frames; what builds the strands and
  the simulation, ``timeline_fixed``, may not), so a frame's hair depends only on its time;
- tubes (4.3.1-4.3.2): :mod:`.techniques.hair_tubes`, ``hair_samples`` spline samples swept by a
  ``sides``-gon tapered by the quadratic ``taper``, built every frame by compute shaders where
  the context has them (:class:`.techniques.hair_tubes.GpuTubes`), else by numpy; the tubes
  of the frame before kept beside them give the ``taa`` effect's motion vectors the hair's
  own motion (:class:`.state.HairMotion`);
- shading (4.3.3-4.3.6): X-toon (:mod:`.techniques.xtoon`) through the ``toon_strands`` model:
  the hair's specular (the band of ``specular_intensity`` and ``specular_exponent``, or the
  ramp's specular metric) along its strands, Kajiya-Kay's sin(T, H) for N.H, the head's band of
  ``skin_specular_intensity`` and ``skin_specular_exponent`` on its normal;
- outlines (4.3.7, image space): the G-buffer datum ``strand_id`` (0 on the head; on the hair
  1 + the object's first id + the strand's index, and the same of its clump: k-means clusters
  of about ``clump_size`` strands) lets the ``edges`` effect outline the hair against the
  head and the background and clumps where they overlap, not every strand;
- silhouette strokes (4.3.7, object space): :mod:`.techniques.hair_silhouettes` with
  ``silhouettes = true``, strokes ``stroke_width`` pixels wide in ``stroke_color`` along the
  tubes' silhouette edges, faded toward the roots by the quadratic ``stroke_fade``; drawn over
  the lit image (deferred: the material phase, visible by the G-buffer's strand ids; forward:
  after the lit hair, by the depth buffer).

The package: ``params.py`` (the parameters and the limits), ``state.py`` (the hair over time,
the material's simulation), ``passes.py`` (the tubes as an input, the hatching and the
strokes), this module (the material).

The tubes carry each vertex's strand in the vertex format's comb slot (the hair has no comb):
``comb.x`` the strand's index, ``comb.y`` the parameter along it, ``comb.z`` its clump; ``uv``
is (along, around).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from deferred.api import (
    GBufferData,
    InputError,
    Material,
    RenderWork,
    SurfacePasses,
    Work,
    WorkObject,
    builtin_head_spheres,
    check_image,
    materials,
)

from ..shading_models import Toon
from ..techniques.hair_clumps import strand_clumps
from ..techniques.hair_strands import grow_strands, load_strands, resample_strand, scalp_roots
from ..techniques.xtoon import XTOON_UNIFORM_OVERRIDES, XToonRamp
from .params import (
    SILHOUETTE_TRIANGLE_SECONDS,
    STRAND_IDS,
    TUBE_TRIANGLE_SECONDS,
    CartoonHairParams,
    tube_counts,
)
from .passes import TUBES, HairStrokes
from .state import DYNAMICS, HairMotion, hair_shape

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject

SURFACE = "materials/cartoon_hair/surface.glsl"
STRAND_ID = GBufferData("strand_id", "RG32F", ("id", "clump"),
                        "cartoon_hair: 1 + the object's first id + the strand's index on "
                        "hair, and the same of the strand's clump; 0 elsewhere")


@materials.register
class CartoonHairMaterial(Material):
    name = "cartoon_hair"
    Params = CartoonHairParams
    surface_shader = SURFACE
    shading_model = "toon_strands"
    gbuffer_data = (STRAND_ID,)
    uniform_overrides = {
        **XTOON_UNIFORM_OVERRIDES,
        **{name: None for name in (
            "skin_color", "strands_file", "strands", "length", "segments", "style", "parting",
            "seed", "edge_stiffness", "bend_stiffness", "torsion_stiffness",
            "anchor_stiffness", "anchor_curve", "keyframes", "key_times", "gravity", "wind",
            "drag", "time_step", "settle", "collision_spheres", "hair_samples", "sides",
            "radius", "taper", "clump_size", "skin_specular_intensity",
            "skin_specular_exponent",
            "silhouettes", "stroke_width", "stroke_world_width", "stroke_color", "stroke_fade",
            "hatching",
            "hatching_strength", "hatching_scale", "hatching_width")},
        "color": lambda value: {},  # the head's pass takes skin_color, the hair's color
    }
    # read once, at t = 0: the strands, the simulation's structure and the tubes' topology
    # (the dynamics' parameters follow the timeline step by step: HairState.physics_at)
    timeline_fixed = ("strands_file", "strands", "length", "segments", "style", "parting",
                      "seed", "clump_size", "keyframes", "key_times", "hair_samples", "sides",
                      "collision_spheres", "time_step", "settle")
    # the head's surface, then the tubes' (its second surface), then their strokes
    techniques = (SurfacePasses(), SurfacePasses(name="hair", inputs=(TUBES,), shape=TUBES),
                  HairStrokes())
    # the strands reach up to their length beyond the head, and move on their own
    motion = HairMotion("length")
    simulation = DYNAMICS

    def check_files(self, where: str | None) -> None:
        super().check_files(where)
        params = self.params

        def at(key: str) -> str:
            return f"{where}.{key}" if where else key

        strands = params.strands
        if params.strands_file is not None:
            strands = len(load_strands(self.file_parameter(params.strands_file, "strand file",
                                                           at("strands_file")),
                                       at("strands_file")))
        for index, name in enumerate(params.keyframes):
            key = at(f"keyframes[{index}]")
            pose = load_strands(self.file_parameter(name, "strand file", key), key)
            if len(pose) != strands:
                source = "strands_file" if params.strands_file is not None else "strands"
                raise InputError(f"{Path(name).name} has {strand_count(len(pose))}; the hair has "
                                 f"{strands:,} ({source}): a keyframe poses each strand", key)
        if params.ramp_image is not None:
            check_image(self.file_parameter(params.ramp_image, "ramp image", at("ramp_image")),
                        at("ramp_image"))

    def xtoon_ramp(self) -> XToonRamp:
        image = None if self.params.ramp_image is None else \
            self.resolve_path(self.params.ramp_image)
        return XToonRamp.from_params(self.params, image, self.key_where("ramp_image"))

    def uniforms(self, frame: Frame) -> dict[str, Any]:  # the ramp's layer: the scene's
        return {**super().uniforms(frame), "u_hair": False, "u_strand_base": 0.0,
                "u_color": self.params.skin_color,
                "u_specular_intensity": self.params.skin_specular_intensity,
                "u_specular_exponent": self.params.skin_specular_exponent,
                "u_ramp_row": Toon.xtoon_row(frame.scene, self.xtoon_ramp())}

    # -- the strands ----------------------------------------------------------------------
    def spheres(self, obj: SceneObject) -> np.ndarray:
        """Object-space collision spheres: the params', or builtin:head's, or none."""
        return self.spheres_of(obj.mesh.name)

    def spheres_of(self, mesh_name: str) -> np.ndarray:
        """The collision spheres on the mesh named ``mesh_name`` (a spec names it too)."""
        if self.params.collision_spheres is not None:
            return np.asarray(self.params.collision_spheres, np.float64).reshape(-1, 4)
        if mesh_name.partition("?")[0] == "builtin:head":
            return builtin_head_spheres()
        return np.zeros((0, 4))

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """The head, then the tubes drawn (with the hatching, a second pass over them) and
        their silhouette strokes, each a sample."""
        p = self.params
        strands, _ = hair_shape(self)
        _, triangles = tube_counts(strands, p)
        shape = f"{strands:,} strands x {p.hair_samples} samples x {p.sides} sides"
        passes = 1 + (p.hatching != "none")
        works = [*super().work(obj, job),
                 Work(f"{obj.label}: tubes of {shape}{', hatched' * (passes > 1)}",
                      triangles * passes, TUBE_TRIANGLE_SECONDS, obj.key("strands"))]
        if p.silhouettes:
            works.append(Work(f"{obj.label}: silhouettes of {shape}", triangles,
                              SILHOUETTE_TRIANGLE_SECONDS, obj.key("silhouettes")))
        return works

    def rest_strands(self, obj: SceneObject) -> np.ndarray:
        """The style: ``(S, P, 3)`` object-space strands, root first."""
        p = self.params
        if p.strands_file is not None:
            where = self.key_where("strands_file")
            strands = load_strands(self.resolve_path(p.strands_file), where)
            if len(strands) >= STRAND_IDS:
                raise InputError(f"{len(strands):,} strands; a hair object holds fewer than "
                                 f"{STRAND_IDS:,}", where)
            return strands
        roots = scalp_roots(obj.mesh, p.strands, p.seed)
        return grow_strands(roots, p.length, p.segments, p.style, p.seed, self.spheres(obj),
                            p.parting)

    def clumps(self, rest: np.ndarray) -> np.ndarray:
        """``(S,)``: each rest strand's clump (:func:`.techniques.hair_strands.strand_clumps`,
        about ``clump_size`` strands a clump): the edges effect outlines clumps, not strands."""
        return strand_clumps(rest, self.params.clump_size, self.params.seed)

    def keyframe_strands(self, shape: tuple[int, ...]) -> np.ndarray:
        """The keyframes' strands, each resampled to the rest strands' points."""
        poses = []
        for index, name in enumerate(self.params.keyframes):
            where = self.key_where(f"keyframes[{index}]")
            strands = load_strands(self.resolve_path(name), where)
            if len(strands) != shape[0]:
                raise InputError(f"{Path(name).name} has {strand_count(len(strands))}; the "
                                 f"hair has {shape[0]:,}", where)
            poses.append(np.stack([resample_strand(s, shape[1]) for s in strands]))
        return np.stack(poses)


def strand_count(count: int) -> str:
    return f"{count:,} strand{'s' * (count != 1)}"
