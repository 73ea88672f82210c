"""Temporal anti-aliasing (``[[effect]] type = "taa"``): each frame's projection moves by a
sub-pixel offset of the Halton (2, 3) sequence, and the frame is blended with the history of
the frames before it, reprojected by per-pixel motion vectors (Karis, "High Quality Temporal
Supersampling", SIGGRAPH 2014; Pedersen, "Temporal Reprojection Anti-Aliasing in INSIDE", GDC
2016).

Passes:
- ``motion.camera`` / ``motion.objects`` (after the opaque geometry: the screen phase, or the
  end of the forward phase): the :data:`~deferred.api.MOTION` target, what the camera alone
  moves (from the depth; the background as directions), then every object over it, its mesh
  pushed out by what its material draws beyond it (:meth:`~deferred.api.Motion.extent` of
  its material's ``motion``: fur shells and fins, hair) with this frame's and the last
  frame's model and view-projection (``common/motion.glsl``), and the meshes it draws that move
  on their own (:meth:`~deferred.api.Motion.surfaces`: hair tubes) from their surface of the
  frame before. Materials change nothing else: the framework sets ``u_previous_model`` and
  ``u_previous_view_projection``.
- ``post.taa`` (before tone mapping, on the linear composite): the history reprojected,
  clipped to the current 3x3 neighbourhood in YCoCg and blended (``effects/taa/taa_resolve.frag``);
- ``post.taa_sharpen``: the result into the composite, optionally sharpened.

The history starts again (the frame alone) on a cut, the camera turning or moving more than
``cut_angle`` / ``cut_distance`` in a frame, and on a seek: a time before the last frame's or
a step more than ``max_step`` (a still frame, the same time again, keeps it, and so does a step
of another length than the last one's). Per-sample patterns follow the sample index since it
started: the stipple's parity (``materials/techniques/stipple.glsl``) covers every pixel of its 2x2
tile over four frames, so the history integrates it.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import moderngl
import numpy as np
from pydantic import Field

from deferred.api import (
    COMPOSITE,
    DEPTH,
    MOTION,
    MOTION_SPEC,
    Effect,
    EffectParams,
    Frame,
    FrameMoment,
    FullscreenPass,
    Order,
    Phase,
    Pipeline,
    RenderPass,
    Scene,
    TargetSpec,
    effects,
    halton,
)

TAA_RESOLVED = "taa_resolved"
TAA_HISTORY = "taa_history"
RESOLVED_SPEC = TargetSpec(4, "f2", "temporal anti-aliasing: the resolved frame (linear HDR)")
HISTORY_SPEC = TargetSpec(4, "f4", "temporal anti-aliasing: the next history (linear RGB, "
                                   "samples averaged)")
ORDER_BEFORE_TONEMAP = Order.FIRST - 1  # on the linear composite, before tone mapping


class TAAParams(EffectParams):
    feedback: float = Field(0.9, ge=0.0, le=0.99,
                            description="the history's weight where the pixel moves")
    still_samples: int = Field(64, ge=1, le=4096,
                               description="samples averaged where the pixel is still")
    clamp: Literal["variance", "minmax"] = Field(
        "variance", description="history clipping box in YCoCg: variance (within min/max) "
                                "or min/max of the 3x3 neighbourhood")
    variance_gamma: float = Field(1.25, gt=0.0, le=8.0,
                                  description="variance box half-width, in standard deviations")
    sharpen: float = Field(0.0, ge=0.0, le=1.0, description="unsharp mask of the result (0 = off)")
    jitter_samples: int = Field(8, ge=1, le=256,
                                description="length of the Halton (2, 3) jitter sequence")
    cut_angle: float = Field(20.0, gt=0.0, le=180.0,
                             description="a camera turning more in a frame is a cut (degrees)")
    cut_distance: float = Field(0.25, gt=0.0,
                                description="a camera moving more in a frame, relative to its "
                                            "distance to the target, is a cut")
    max_step: float = Field(0.25, gt=0.0,
                            description="a step in time longer than this is a seek (seconds)")


def camera_cut(previous: Any, camera: Any, angle_degrees: float, distance: float) -> bool:
    """Whether the camera jumped between two frames: its view direction turned by more than
    ``angle_degrees``, its position moved by more than ``distance`` times its distance to its
    target, or its field of view changed by more than a quarter."""
    if previous is camera:
        return False
    before = np.subtract(previous.target, previous.position)
    after = np.subtract(camera.target, camera.position)
    reach = float(np.linalg.norm(before))
    cosine = float(np.dot(before, after) / max(reach * float(np.linalg.norm(after)), 1e-12))
    if math.degrees(math.acos(min(1.0, max(-1.0, cosine)))) > angle_degrees:
        return True
    moved = float(np.linalg.norm(np.subtract(camera.position, previous.position)))
    if moved > distance * max(reach, 1e-9):
        return True
    return not 0.8 <= camera.fov / previous.fov <= 1.25


class MotionObjectsPass(RenderPass):
    """Every object's motion over the camera's (``screen/motion_objects``): depth-tested against
    the opaque depth, nearer by a little (the mesh pushed out by nothing draws where its own
    surface is)."""

    order = Order.LAST

    def __init__(self, name: str, phase: Phase):
        self.name = name
        self.phase = phase
        self.reads = (DEPTH, MOTION)  # tests the depth, draws over the camera's motion
        self.writes = (MOTION,)

    def execute(self, frame: Frame) -> None:
        frame.use_framebuffer((MOTION,), DEPTH, depth_write=False)
        frame.set_state(depth_test=True, depth_func="lequal", cull="back", blend=None,
                        depth_offset=(-1.0, -4.0))
        for obj in frame.scene.objects:
            # a skinned mesh's motion reads its surface of the frame before too
            defines = {"PREVIOUS_SURFACE": "1"} if obj.skin_matrices is not None else {}
            motion = obj.material.motion
            offsets = motion.offsets(frame, obj)  # the reach moving on its own (wind)
            uniforms: dict[str, Any] = {"u_motion_extent": float(motion.extent(obj))}
            textures = {}
            if offsets is not None:
                defines = {**defines, "MOTION_OFFSETS": "1"}
                uniforms["u_motion_offset_stride"] = int(offsets.stride)
                textures = {"u_motion_offsets": offsets.current,
                            "u_previous_motion_offsets": offsets.previous}
            program = frame.shaders.program("effects/taa/motion_objects.vert",
                                            "effects/taa/motion_objects.frag",
                                            defines=defines or None)
            frame.bind(program, uniforms, textures, offered=frame.object_uniforms(obj))
            frame.draw_mesh(obj.mesh, program)
            surfaces = motion.surfaces(frame, obj)  # drawn as they are, over the reach
            if surfaces:
                program = frame.shaders.program("effects/taa/motion_objects.vert",
                                                "effects/taa/motion_objects.frag",
                                                defines={"PREVIOUS_SURFACE": "1"})
                frame.bind(program, {"u_motion_extent": 0.0},
                           offered=frame.object_uniforms(obj))
                for surface in surfaces:
                    surface.render(program)


class TAAResolvePass(FullscreenPass):
    """The resolve, holding the history from one frame to the next (a texture of its own: no
    pass of a frame may read what an earlier frame left in a target)."""

    def __init__(self, effect: TAA):
        super().__init__("post.taa", Phase.POST, "effects/taa/taa_resolve.frag",
                         {"u_composite": COMPOSITE, "u_motion": MOTION},
                         (TAA_RESOLVED, TAA_HISTORY),
                         creates={TAA_RESOLVED: RESOLVED_SPEC, TAA_HISTORY: HISTORY_SPEC},
                         uniforms=self._uniforms, order=ORDER_BEFORE_TONEMAP)
        self.effect = effect
        self._history: HeldHistory | None = None
        self._has_history = False

    def _uniforms(self, frame: Frame) -> dict[str, Any]:
        return {**self.effect.uniforms(frame),
                "u_history_valid": bool(frame.history_kept and self._has_history)}

    def execute(self, frame: Frame) -> None:
        size = (frame.width, frame.height)
        held = frame.resources.current(("taa_history", id(self)), size,
                                       lambda ctx: HeldHistory(ctx, size))
        if held is not self._history:  # a new size or renderer: no history yet
            self._history, self._has_history = held, False
        history = held.texture
        program = frame.shaders.program(self.vertex, self.fragment, defines=self.defines)
        frame.use_framebuffer(self.outputs)
        frame.set_state(depth_test=False, blend=None)
        frame.bind(program, self._uniforms(frame),
                   {**{u: frame.target(t) for u, t in self.inputs.items()},
                    "u_history": history})
        frame.draw_fullscreen(program)
        # the next frame's history: a copy of what this one wrote
        frame.ctx.copy_framebuffer(held.framebuffer, frame.targets.framebuffer((TAA_HISTORY,)))
        frame.gl.park()  # the copy bound framebuffers behind the device's back
        self._has_history = True


class HeldHistory:
    """The history texture (RGBA32F, bilinear) and a framebuffer to copy into it."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]):
        self.texture = ctx.texture(size, 4, dtype="f4")
        self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.texture.repeat_x = self.texture.repeat_y = False
        self.framebuffer = ctx.framebuffer(color_attachments=[self.texture])

    def release(self) -> None:
        self.framebuffer.release()
        self.texture.release()


@effects.register
class TAA(Effect):
    name = "taa"
    Params = TAAParams
    temporal = True
    uniform_overrides = {
        "clamp": lambda value: {"u_clamp": 0 if value == "variance" else 1},
        "jitter_samples": None, "cut_angle": None, "cut_distance": None, "max_step": None,
        "sharpen": None,  # the sharpen pass's own
    }

    def held_memory(self, size: tuple[int, int]) -> dict[str, int]:
        return {f"taa history {id(self)}": size[0] * size[1] * 16}  # HeldHistory's RGBA32F

    def jitter(self, index: int) -> tuple[float, float]:
        k = index % self.params.jitter_samples + 1
        return (halton(k, 2) - 0.5, halton(k, 3) - 0.5)

    def keeps_history(self, previous: FrameMoment, current: FrameMoment) -> bool:
        step = current.step
        # A step back or a long one is a seek; a step of another length is not: a viewer plays
        # by the window's frames, whose time steps vary, and the motion vectors follow it.
        if step is None or step < 0.0 or step > self.params.max_step:
            return False
        return not camera_cut(previous.camera, current.camera, self.params.cut_angle,
                              self.params.cut_distance)

    def passes(self, scene: Scene, pipeline: str) -> list[RenderPass]:
        # after the opaque depth: the deferred G-buffer (before any stipple sample), or every
        # forward pass
        phase = Phase.SCREEN if pipeline == Pipeline.DEFERRED else Phase.FORWARD
        camera = FullscreenPass(
            "motion.camera", phase, "effects/taa/motion_camera.frag", {"u_depth": DEPTH}, (MOTION,),
            creates={MOTION: MOTION_SPEC}, order=Order.LAST,
            uniforms=lambda frame: {"u_camera_to_world": np.linalg.inv(frame.view)})
        return [
            camera,
            MotionObjectsPass("motion.objects", phase),
            TAAResolvePass(self),
            FullscreenPass("post.taa_sharpen", Phase.POST, "effects/taa/taa_sharpen.frag",
                           {"u_taa_resolved": TAA_RESOLVED}, (COMPOSITE,),
                           uniforms=lambda frame: {"u_sharpen": self.params.sharpen},
                           order=ORDER_BEFORE_TONEMAP),
        ]
