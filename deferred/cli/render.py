"""``deferred render``: a scene to an image, a numbered image sequence or a video. Every option
is checked before the scene loads where it can be, and before the renderer starts where it
needs the scene."""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import click

from deferred.cli import options
from deferred.cli.budget import StepClock, before_meshes, check_render, warn
from deferred.cli.farm_options import check_farm_options, farm_options
from deferred.cli.options import FiniteFloat, check_not_inputs, parse_size_option, stderr
from deferred.cli.view_option import (
    LISTING,
    RENDER_HELP,
    capture_view,
    check_one_buffer,
    material_view,
    print_view_names,
    view_option,
    view_pass,
    write_captured_view,
)
from deferred.errors import InputError
from deferred.io.images import write_image
from deferred.io.paths import check_output_path
from deferred.io.progress import Progress
from deferred.names import CascadeUpdates
from deferred.scene.loader import load_scene

if TYPE_CHECKING:
    from deferred.io.cost import Prediction
    from deferred.render.renderer import Renderer
    from deferred.scene import Scene


@dataclass(frozen=True)
class RenderJob:
    """What one ``render`` asked for, its options checked as far as they can be without the
    scene."""

    scene: str | None
    out: Path
    kind: str  # image, sequence or video (deferred.io.paths.output_kind)
    pipeline: str
    size: str | None  # as given: read once the scene has loaded, as the scene's size is
    times: list[float]
    fps: float
    start_time: float
    turntable: int | None
    samples: int
    light_path: str | None
    strict: bool
    view_name: str | None
    gltf_camera: str | None = None
    animation: str | None = None
    workers: int | None = None  # --workers: local worker processes
    ray: str | None = None  # --ray: the cluster's address, "" for a local instance
    resume: bool = False

    @property
    def farmed(self) -> bool:
        """Whether the frames go to workers (and a manifest): --workers, --ray, --resume."""
        return self.workers is not None or self.ray is not None or self.resume

    @property
    def frames(self) -> int:
        return len(self.times)


@dataclass(frozen=True)
class Rendered:
    """What the summary line says of a finished render."""

    size: tuple[int, int]
    light_path: str
    written: str
    frame_ms: list[float]


@click.command()
@options.scene_argument
@click.option("-o", "--output", default="render.png", show_default=True,
              help="Output: an image, .png (sRGB 8-bit) or .exr (linear float); a numbered "
                   "sequence, out_####.png (the run of # becomes the frame number); or a "
                   "video, .mp4 (H.264) or .gif.")
@options.pipeline_option
@options.size_option()
@click.option("--frames", type=click.IntRange(min=1, max=100_000), default=1, show_default=True,
              help="Render this many frames, frame i at --time + i / --fps seconds, to a "
                   "numbered sequence (a # pattern) or a video: one image holds one frame.")
@click.option("--fps", type=FiniteFloat(min=0.0, min_open=True, max=1000.0), default=24.0,
              show_default=True, help="Frames per second: the time step and the video's rate.")
@options.time_option("Time of the first frame (the scene's [[event]] timeline, animated "
                     "materials).")
@click.option("--turntable", type=click.IntRange(min=1, max=100_000), metavar="N",
              help="Orbit the camera once about the vertical through its target over N frames "
                   "(the times --frames N gives; frame N would be frame 0 again), to a # "
                   "pattern or a video.")
@click.option("--samples", type=click.IntRange(min=1, max=1024), default=1, show_default=True,
              help="Average each frame over this many renders moved by sub-pixel offsets "
                   "(Halton 2, 3), in linear light: anti-aliasing that converges to a "
                   "supersampled frame.")
@options.light_path_option
@options.strict_option
@view_option(RENDER_HELP)
@options.gltf_options
@farm_options
def render(scene: str | None, output: str, pipeline: str, size: str | None, frames: int,
           fps: float, start_time: float, turntable: int | None, samples: int,
           light_path: str | None, strict: bool, view_name: str | None,
           gltf_camera: str | None, animation: str | None, workers: int | None,
           ray: str | None, resume: bool) -> None:
    """Render SCENE (a TOML file or a glTF file; the built-in demo when omitted) to an image,
    a numbered image sequence or a video."""
    if view_name == LISTING:
        print_view_names(scene, pipeline, light_path)
        return
    if ray and scene is None and Path(ray).is_file():  # `--ray SCENE`: the scene, no address
        scene, ray = ray, ""
    job = render_job(scene, output, pipeline, size, frames, fps, start_time, turntable, samples,
                     light_path, strict, view_name)
    job = replace(job, gltf_camera=gltf_camera, animation=animation, workers=workers, ray=ray,
                  resume=resume)
    check_farm_options(job.kind, workers, ray, resume)
    with Progress("render", stderr) as progress:
        rendered = run_render(job, progress)
    stderr.print(summary(job, rendered), markup=False, highlight=False)


def render_job(scene: str | None, output: str, pipeline: str, size: str | None, frames: int,
               fps: float, start_time: float, turntable: int | None, samples: int,
               light_path: str | None, strict: bool, view_name: str | None) -> RenderJob:
    """The options as a :class:`RenderJob`; ``InputError`` for any that cannot go together."""
    from deferred.io.paths import output_kind
    from deferred.io.video import check_video_writer, frame_times

    options.check_light_path_option(pipeline, light_path)
    out = check_output_path(output)
    kind = output_kind(out)
    if turntable is not None:
        frames = _turntable_frames(out, kind, frames, turntable)
    times = frame_times(frames, fps, start_time)
    check_one_buffer(view_name, kind, samples, frames)
    if kind == "image" and frames > 1:
        raise InputError(f"{frames} frames cannot go to one image, {out.name}: use a # pattern "
                         f"such as {out.stem}_####{out.suffix}, or .mp4/.gif", "--frames")
    if kind == "video":
        check_video_writer(out)  # a missing extra is said before the scene loads
    return RenderJob(scene=scene, out=out, kind=kind, pipeline=pipeline, size=size, times=times,
                     fps=fps, start_time=start_time, turntable=turntable, samples=samples,
                     light_path=light_path, strict=strict, view_name=view_name)


def _turntable_frames(out: Path, kind: str, frames: int, turntable: int) -> int:
    """--turntable N renders N frames, to a sequence or a video."""
    source = click.get_current_context().get_parameter_source("frames")
    if source != click.core.ParameterSource.DEFAULT and frames != turntable:
        raise InputError(f"--turntable {turntable} renders {turntable} frames; leave "
                         "--frames out", "--frames")
    if kind == "image":
        raise InputError(f"a turntable is {turntable} frames and {out.name} holds one "
                         f"image: use a # pattern such as {out.stem}_####{out.suffix}, or "
                         ".mp4/.gif", "--turntable")
    return turntable


def run_render(job: RenderJob, progress: Progress) -> Rendered:
    """Load the scene, render every frame of ``job`` and write them."""
    from deferred.render.renderer import Renderer
    from deferred.render.samples import check_samples_memory

    progress.status(f"loading {job.scene or 'the demo scene'} (meshes, UV unwraps)")
    loaded, size = _load(job)
    loaded, buffer = material_view(loaded, job.view_name, job.pipeline)
    predicted, long = check_render(loaded, size or loaded.size, job.samples, job.times,
                                   job.pipeline, size is not None)
    check_samples_memory(size or loaded.size, job.samples)  # the renderer's are counted later
    if job.farmed:
        warn(long)
        return _render_farmed(job, loaded, size, progress)
    progress.status("starting the renderer")
    with Renderer(loaded, job.pipeline, size, strict=job.strict or None,
                  light_path=job.light_path) as renderer:
        renderer.check_times(job.times)  # a simulation cannot reach the last frame: refuse now
        check_samples_memory(renderer.size, job.samples, renderer.memory_bytes())
        warn(long)  # every check passed: the work starts
        if job.kind == "image":
            frame_ms = _render_image(renderer, loaded, job, buffer, progress, predicted)
            written = str(job.out)
        else:
            written, frame_ms = _render_animation(renderer, job, progress, predicted)
    return Rendered(renderer.size, renderer.light_path, written, frame_ms)


def _load(job: RenderJob) -> tuple[Scene, tuple[int, int] | None]:
    """The scene, set up as ``job`` asks, and the size that overrides its own; ``InputError``
    where an output would replace one of its files, a video cannot hold its frames or the work
    is past the time budget (both said before the meshes load)."""
    size = parse_size_option(job.size)
    weigh = before_meshes(size, job.samples, job.times, job.pipeline)

    def check(scene: Scene, objects: list) -> None:
        _check_video(job, size or scene.size)
        weigh(scene, objects)  # a scene too heavy for the time budget: before its meshes

    chosen = {key: value for key, value in (("camera", job.gltf_camera),
                                            ("animation", job.animation)) if value is not None}
    loaded = load_scene(job.scene, **chosen, before_meshes=check)
    if job.turntable is not None:
        loaded.set_turntable(job.turntable / job.fps, job.start_time)
    check_not_inputs(_outputs(job), loaded, job.scene, "-o")
    _check_video(job, size or loaded.size)  # a glTF file is a scene without before_meshes
    return loaded, size


def _check_video(job: RenderJob, size: tuple[int, int]) -> None:
    """A video's size and, for a GIF, the memory of its frames."""
    from deferred.io.video import check_animation_memory, check_video_size

    if job.kind == "video":
        check_video_size(job.out, size)
        check_animation_memory(job.out, size, job.frames)


def _outputs(job: RenderJob) -> list[Path]:
    """Every file ``render -o`` writes: a sequence's frames, or the one file."""
    if job.kind != "sequence":
        return [job.out]
    from deferred.io.paths import expand_pattern

    return [expand_pattern(job.out, index) for index in range(job.frames)]


def _render_image(renderer: Renderer, loaded: Scene, job: RenderJob, buffer: str | None,
                  progress: Progress, predicted: Prediction) -> list[float]:
    """The one frame to ``job.out``, the final image or the buffer ``buffer``: its time in ms.
    Written while the renderer lives: the result may read its buffers lazily."""
    captured_after = view_pass(renderer, buffer) if buffer is not None else None  # bad names fail
    at = job.times[0]
    start = time.perf_counter()
    if buffer is not None:
        progress.status(first_frame_stage(loaded))
        capture = capture_view(renderer, loaded, captured_after, at, job.fps)
    elif job.samples > 1:
        on_sample = _counted_steps(progress, job.samples, "samples", f"rendering {job.out.name}",
                                   predicted, first_frame_stage(loaded))
        result = renderer.render_samples(job.samples, at, on_sample)
    else:
        progress.status(first_frame_stage(loaded))
        result = renderer.render(readback=True, time=at)
    renderer.gl.ctx.finish()
    frame_ms = [(time.perf_counter() - start) * 1000.0]
    progress.status(f"writing {job.out.name}")
    if buffer is not None:
        write_captured_view(job.out, capture, buffer)
    elif job.out.suffix.lower() == ".exr":
        write_image(job.out, result.hdr, channels=("R", "G", "B", "A"))
    else:
        write_image(job.out, result.image)
    return frame_ms


def first_frame_stage(loaded: Scene) -> str:
    """What the first render of a command does besides drawing."""
    simulated = any(obj.material.simulation is not None for obj in loaded.objects)
    return "the first frame: compiling shaders" + (", simulating" if simulated else "")


def _counted_steps(progress: Progress, total: int, unit: str, text: str,
                   predicted: Prediction, first: str) -> Callable[[int], None]:
    """Counted progress of ``total`` samples or frames, the time left from the prediction
    until steps are measured (:class:`StepClock`): the callback to call with the count done."""
    each = predicted.seconds / max(total, 1)
    clock = StepClock(total, each)
    progress.count(total, unit, f"{text} ({first})")
    progress.advance(0, seconds_left=predicted.seconds)
    clock.start()

    def step(done: int) -> None:
        progress.advance(done, text, clock.done(done))

    return step


def _render_animation(renderer: Renderer, job: RenderJob, progress: Progress,
                      predicted: Prediction) -> tuple[str, list[float]]:
    """Every frame of ``job`` to its sequence or video, each averaged over ``job.samples``
    sub-pixel renders: (what was written, the frame times in ms). A sample is a step of the
    progress (frames x samples in all)."""
    from deferred.io.video import AnimationWriter, check_animation_memory, describe_written

    if job.kind == "video":  # the frames a GIF holds with what the renderer holds
        check_animation_memory(job.out, renderer.size, job.frames,
                               renderer_bytes=renderer.memory_bytes())
    out, frame_ms = job.out, []
    with AnimationWriter(out, job.fps) as writer:
        unit = "samples" if job.samples > 1 else "frames"
        step = _counted_steps(progress, job.frames * job.samples, unit, f"rendering {out.name}",
                              predicted, first_frame_stage(renderer.scene))
        for index, at in enumerate(job.times):
            start = time.perf_counter()
            if job.samples > 1:
                averaged = renderer.render_samples(
                    job.samples, at, functools.partial(_after, step, index * job.samples))
                frame_ms.append((time.perf_counter() - start) * 1000.0)
                writer.write(averaged.hdr if writer.wants_hdr else averaged.image)
            else:
                renderer.render(readback=False, time=at)
                renderer.gl.ctx.finish()
                frame_ms.append((time.perf_counter() - start) * 1000.0)
                writer.write(renderer.read_hdr() if writer.wants_hdr else renderer.read_final())
                step(index + 1)
        progress.status(f"writing {out.name}")
        written = writer.close()
    return describe_written(written), frame_ms


def _render_farmed(job: RenderJob, loaded: Scene, size: tuple[int, int] | None,
                   progress: Progress) -> Rendered:
    """The frames rendered by workers (:mod:`deferred.farm`): the scene sent by content."""
    from deferred.farm.bundle import bundle_scene
    from deferred.farm.sequence import make_pool, render_sequence
    from deferred.farm.worker import FrameJob
    from deferred.scene.timeline import SceneEvaluator

    if loaded.shadow_budget.cascade_updates == CascadeUpdates.STAGGERED:
        # a frame would read far cascades its worker drew for other frames
        raise InputError("\"staggered\" makes a frame depend on the frames before it: not "
                         "with --workers, --ray or --resume (every_frame, or leave it out)",
                         f"{loaded.source}: shadows.cascade_updates")
    loaded.check_tracks(job.times)  # as the renderer does, before any worker starts
    SceneEvaluator(loaded).check_simulation_times(max(job.times), "--time")
    frames = FrameJob(bundle_scene(job.scene, loaded), job.pipeline, size, job.times, job.fps,
                      job.start_time, job.samples, job.light_path, job.strict, job.turntable,
                      job.gltf_camera, job.animation,
                      job.out.suffix.lower() if job.kind == "sequence" else ".png")
    temporal = any(effect.temporal for effect in loaded.effects)
    result = render_sequence(frames, job.out, job.kind,
                             functools.partial(make_pool, frames, job.workers, job.ray),
                             progress, job.resume, temporal)
    from deferred.io.video import describe_written

    return Rendered(size or loaded.size, result.light_path or "-",
                    describe_written(result.written), result.frame_ms)


def _after(step: Callable[[int], None], before: int, count: int) -> None:
    step(before + count)


def summary(job: RenderJob, rendered: Rendered) -> str:
    """``wrote OUT (WxH, PIPELINE, PATH lights[, view V][, t = ...], TIMING)``."""
    frame_ms = rendered.frame_ms
    timing = f"{min(frame_ms):.1f} ms" if job.frames == 1 and frame_ms else \
        f"median {sorted(frame_ms)[len(frame_ms) // 2]:.1f} ms over {len(frame_ms)} frames" \
        if frame_ms else "every frame was done already"
    shown = f", view {job.view_name}" if job.view_name is not None else ""
    clock = ""
    if job.frames > 1 or job.start_time > 0.0:
        times = job.times
        clock = f", t = {times[0]:g}" + (f"..{times[-1]:g} s at {job.fps:g} fps"
                                         if job.frames > 1 else " s")
    width, height = rendered.size
    return (f"wrote {rendered.written} ({width}x{height}, {job.pipeline}, "
            f"{rendered.light_path} lights{shown}{clock}, {timing})")
