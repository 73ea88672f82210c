"""shell_fur's passes beyond its surface: the skin and the N texture layers (Silva et al.
section 4) and the fins, lit in the material phase from the fur light gathered once a frame
(``techniques/fur_light.py``), in the forward pipeline by themselves; and what every pass of an
object reads of its state (:class:`StateTextures`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from deferred.api import COMPOSITE, PassInput, Phase, RenderPass, Technique

from ..techniques.fins import FinPass
from ..techniques.fur import tiles_per_unit, vertex_constants
from ..techniques.fur_light import FurLight, fur_light_pass
from ..techniques.shells import ShellPass
from .params import ShellFurParams
from .state import SIMULATION

if TYPE_CHECKING:
    import moderngl

    from deferred.api import Frame, Material, SceneObject

FUR_VERTEX = "materials/shell_fur/fur.vert"
SHELL_FRAGMENT = "materials/shell_fur/shell.frag"
FORWARD_SHELL_FRAGMENT = "materials/shell_fur/forward_shell.frag"
CHORD = {"STRAND_CHORD": "1"}  # the strand's chord as its tangent (fur.vert)


class StateTextures(PassInput):
    """An input of every pass of a shell_fur object: its state's textures (the wetness mask and
    the strands) at the frame's time; with ``clumps`` (the layers and fins, which clump) whether
    the mesh's UVs wrap and the fur's density over them."""

    def __init__(self, clumps: bool = False):
        self.clumps = clumps

    def textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        state = SIMULATION.state(frame, obj)
        return {"u_wetness_mask": state.mask_texture, "u_strand_tips": state.tips_texture}

    def uniforms(self, frame: Frame, obj: SceneObject) -> dict[str, Any]:
        if not self.clumps:
            return {}
        state = SIMULATION.state(frame, obj)
        # the world density over the UVs: tiles per world unit x world units per UV unit
        return {"u_mask_wrap": tuple(float(w) for w in state.wrap),
                "u_fur_uv_tiles": tiles_per_unit(obj.params) * state.world_per_uv}


STATE = StateTextures()
CLUMPED_STATE = StateTextures(clumps=True)


def layer_layout(count: float, shell_range: tuple[float, float] = (0.0, 1.0),
                 debug: str = "none") -> list[tuple[float, float] | None]:
    """(h, fade) of each layer drawn for a continuous layer count N: the skin (h = 0, index 0),
    then Silva's layers h = (1 + n)/N, n = 0 .. ceil(N) - 1, the last kept at h <= 1 and faded
    by N's fraction, so the level of detail never pops. None: not drawn (outside shell_range, or
    hidden by a debug view)."""
    drawn = math.ceil(count - 1e-9)
    layers = [(0.0, 1.0)] + [(min((1 + n) / count, 1.0),
                              1.0 if n < drawn - 1 else count - (drawn - 1))
                             for n in range(drawn)]
    low, high = shell_range
    if debug in ("shell_count", "wetness"):
        return [layers[0]] + [None] * drawn
    in_range = [k for k, (h, _) in enumerate(layers) if low <= h <= high]
    if debug == "single_shell":
        shown = {in_range[len(in_range) // 2]} if in_range else set()
    else:
        shown = set(in_range)
    return [layer if k in shown else None for k, layer in enumerate(layers)]


class ShellFurLayerPass(ShellPass):
    """The skin and the N layers (Silva's spacing, :func:`layer_layout`)."""

    vertex = FUR_VERTEX

    def layout(self, count: float, params: ShellFurParams) -> list[tuple[float, float] | None]:
        # no layers, not even the skin, without shells
        return layer_layout(count, params.shell_range, params.debug) if count > 0 else []

    def slabs(self, count: float) -> float:
        return count  # N layers over the skin: each stands for 1/N of the fur


class FurLayers(Technique):
    """The fins (along the strand's chord) and the layers: in the material phase lit from the
    material's fur light (``fur_light`` names its gather, one per material class, as its
    G-buffer id is), gathered once for every object's layers and fins (a scene pass); in the
    forward pipeline lighting themselves."""

    def __init__(self, fur_light: str, material: str):
        self.fur_light = fur_light
        self.material = material

    def passes(self, material: Material, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        if phase not in (Phase.MATERIAL, Phase.FORWARD) or material.params.shells == 0:
            return []
        if phase == Phase.MATERIAL:
            prefix, fragment = "", SHELL_FRAGMENT
            inputs: tuple[PassInput, ...] = (FurLight(self.fur_light), CLUMPED_STATE)
        else:
            prefix, fragment, inputs = "forward_", FORWARD_SHELL_FRAGMENT, (CLUMPED_STATE,)
        options = {"fragment": fragment, "colors": (COMPOSITE,), "inputs": inputs,
                   "constants": vertex_constants(obj)}
        passes: list[RenderPass] = []
        if material.params.fins:
            passes.append(FinPass(f"{obj.label}.{prefix}fins", phase, obj, vertex=FUR_VERTEX,
                                  extra_defines={"FIN_STRAND_TANGENT": "1", **CHORD},
                                  **options))
        passes.append(ShellFurLayerPass(f"{obj.label}.{prefix}layers", phase, obj, **options))
        return passes

    def scene_passes(self, objects: Sequence[SceneObject], phase: Phase) -> list[RenderPass]:
        """The fur's light per pixel, gathered once for every object's layers and fins
        (deferred only: forward layers light themselves)."""
        if phase != Phase.MATERIAL or not any(obj.material.params.shells > 0
                                              for obj in objects):
            return []
        return [fur_light_pass(f"material.{self.fur_light}", self.fur_light,
                               objects[0].material.surface_id(), self.material)]
