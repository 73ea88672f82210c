"""A render worker: one scene, one GL context and one warm :class:`Renderer`, rendering the
frames of a sequence that it is given, in any order, each byte-identical to the frame a single
renderer drawing the whole sequence from its first frame writes.

A frame at time t depends on the scene and t alone, except through what a renderer carries
from one frame to the next:

- simulations (shell_fur's strands and wetness, cartoon_hair's chains) step from t = 0 in fixed
  steps, but a frame's advance is one call, and some of its sums (drying, soaking) are taken
  over the steps since the last frame: so before the first frame of a chunk the worker replays
  the frames before it without drawing (:meth:`Renderer.simulate`, cheap beside a frame), and
  the state is the one a single renderer would have;
- a temporal effect (taa) blends each frame into the history of the frames before it, so a
  chunk of such a scene first draws the frames before it (the sequence planner gives a temporal
  scene one chunk: :func:`deferred.farm.sequence.plan_chunks`).

A frame asked for before the renderer's last one starts a new renderer (a retried chunk).
"""

from __future__ import annotations

import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from deferred.errors import DeferredError, InputError
from deferred.farm.bundle import SceneBundle, UnpackedScene

HDR_CHANNELS = ("R", "G", "B", "A")


@dataclass(frozen=True)
class FrameJob:
    """What every worker of a sequence renders: the scene by content and the render's
    options, as ``deferred render`` checked them (picklable: it travels to the workers)."""

    bundle: SceneBundle
    pipeline: str
    size: tuple[int, int] | None
    times: list[float]
    fps: float
    start_time: float
    samples: int = 1
    light_path: str | None = None
    strict: bool = False
    turntable: int | None = None
    gltf_camera: str | None = None
    animation: str | None = None
    suffix: str = ".png"  # the frames' format: .png (sRGB 8-bit) or .exr (the float composite)

    def options(self) -> dict[str, object]:
        """What the manifest records of the options (with the scene's digest apart)."""
        # not the frame count: a longer run of the same frames keeps the ones done (a frame
        # depends on the frames before it, which the same fps and start time make the same)
        return {"pipeline": self.pipeline, "size": list(self.size) if self.size else None,
                "fps": self.fps, "start_time": self.start_time, "samples": self.samples,
                "light_path": self.light_path, "turntable": self.turntable,
                "camera": self.gltf_camera, "animation": self.animation,
                "format": self.suffix}


@dataclass(frozen=True)
class FrameDone:
    """A frame's file, encoded by the worker, and its time to render in ms."""

    index: int
    data: bytes
    ms: float
    worker: str
    light_path: str = ""  # the renderer's, for the command's summary line


@dataclass(frozen=True)
class FrameFailed:
    """A frame that failed for a reason of its own: its number, the message, and whether the
    input was at fault (exit 2) or the render (exit 1)."""

    index: int
    message: str
    bad_input: bool
    worker: str


FrameOutcome = FrameDone | FrameFailed


class FrameWorker:
    """Renders frames of ``job`` (:meth:`frame`) on a renderer it keeps between calls."""

    def __init__(self, job: FrameJob, name: str = "worker"):
        self.job = job
        self.name = name
        self._unpacked: UnpackedScene | None = None
        self._renderer = None
        self._next = 0  # the frame the renderer's simulations and history are ready for
        self._temporal = self._simulated = False
        self._encoded = Path(tempfile.mkdtemp(prefix="deferred-frames-"))

    def _start(self) -> None:
        from deferred.render.renderer import Renderer
        from deferred.scene.loader import load_scene

        self._stop_renderer()
        job = self.job
        if self._unpacked is None:
            self._unpacked = UnpackedScene(job.bundle)
        chosen = {key: value for key, value in (("camera", job.gltf_camera),
                                                ("animation", job.animation)) if value}
        scene = load_scene(self._unpacked.path, **chosen)
        if job.turntable is not None:
            scene.set_turntable(job.turntable / job.fps, job.start_time)
        self._renderer = Renderer(scene, job.pipeline, job.size, strict=job.strict or None,
                                  light_path=job.light_path)
        self._renderer.check_times(job.times)
        self._temporal = any(effect.temporal for effect in scene.effects)
        self._simulated = any(obj.material.simulation is not None for obj in scene.objects)
        self._next = 0

    def frame(self, index: int) -> FrameOutcome:
        """Frame ``index`` of the job as its file's bytes, or why it failed."""
        try:
            if self._renderer is None or \
                    (index < self._next and (self._temporal or self._simulated)):
                self._start()
            self._replay(index)
            start = time.perf_counter()
            pixels = self._draw(index, readback=True)
            ms = (time.perf_counter() - start) * 1000.0
            self._next = index + 1
            return FrameDone(index, self._encode(index, pixels), ms, self.name,
                             self._renderer.light_path)
        except InputError as exc:
            return FrameFailed(index, str(exc), True, self.name)
        except DeferredError as exc:
            return FrameFailed(index, str(exc), False, self.name)
        except Exception as exc:  # noqa: BLE001 - said with the frame's number by the driver
            return FrameFailed(index, f"{type(exc).__name__}: {exc}", False, self.name)

    def _replay(self, index: int) -> None:
        """Bring the renderer to where a single renderer is just before frame ``index``."""
        for earlier in range(self._next, index):
            if self._temporal:
                self._draw(earlier, readback=False)
            elif self._simulated:
                self._renderer.simulate(self.job.times[earlier])
        self._next = max(self._next, index)

    def _draw(self, index: int, readback: bool):
        """Frame ``index`` drawn as ``deferred render`` draws a frame of a sequence."""
        renderer, job = self._renderer, self.job
        at = job.times[index]
        hdr = job.suffix == ".exr"
        if job.samples > 1:
            averaged = renderer.render_samples(job.samples, at)
            return (averaged.hdr if hdr else averaged.image) if readback else None
        renderer.render(readback=False, time=at)
        renderer.gl.ctx.finish()
        if not readback:
            return None
        return renderer.read_hdr() if hdr else renderer.read_final()

    def _encode(self, index: int, pixels) -> bytes:
        from deferred.io.images import write_image

        path = self._encoded / f"frame_{index}{self.job.suffix}"
        write_image(path, pixels, channels=HDR_CHANNELS if self.job.suffix == ".exr" else None)
        try:
            return path.read_bytes()
        finally:
            path.unlink(missing_ok=True)

    def _stop_renderer(self) -> None:
        renderer, self._renderer = self._renderer, None
        if renderer is not None:
            renderer.release()

    def close(self) -> None:
        """Release the renderer and remove the worker's folders."""
        try:
            self._stop_renderer()
        finally:
            if self._unpacked is not None:
                self._unpacked.remove()
            shutil.rmtree(self._encoded, ignore_errors=True)

