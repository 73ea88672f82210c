"""The ``deferred`` command line (README.md, "Command line").

Exit codes: 0 success, 1 a failure while rendering (``dump --compare``: the dumps differ), 2 bad
input. Bad input is one line on stderr naming the file/key and the problem; ``--debug`` shows the
traceback instead. Progress goes to stderr (:mod:`deferred.io.progress`), so does a Python
warning, as one line (``warning: ...``); results (tables, ``--json -``) go to stdout.
"""

from __future__ import annotations

import math
import os
import sys
import time
import traceback
import warnings
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from deferred.errors import DeferredError, InputError, RenderError, ShaderError, one_line
from deferred.interfaces import registry
from deferred.io.images import write_image
from deferred.io.paths import check_output_path
from deferred.io.progress import Progress, duration
from deferred.io.safety import (
    interrupt_exit_code,
    raise_if_stop_requested,
    termination_as_interrupt,
)
from deferred.names import LightPath, Pipeline
from deferred.render.pipeline import PIPELINES
from deferred.scene.loader import load_scene
from deferred.scene.model import parse_size

stderr = Console(stderr=True, soft_wrap=True)  # status lines never wrap on pipes
LIGHT_PATH_CHOICE = click.Choice([path.value for path in LightPath])
LIGHT_PATH_HELP = ("How lights reach the pixels: volumes, tiled or clustered (deferred); naive or "
                   "tiled, i.e. Forward+ (forward). Default: the scene's light_path, else tiled "
                   "where compute shaders exist.")


MAX_PROBLEM_LINES = 50  # a scene file's problems shown; the rest are counted


class Options:
    debug = False


class FiniteFloat(click.FloatRange):
    """A float option within its range that is also finite (click takes "nan" and "inf")."""

    name = "finite float"

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


def _size_option(value: str | None) -> tuple[int, int] | None:
    return None if value is None else parse_size(value)


def _scene(path: str | None):
    return load_scene(path)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks instead of one-line errors.")
@click.version_option(package_name="deferred")
def cli(debug: bool) -> None:
    """A deferred-shading renderer with pluggable materials."""
    Options.debug = debug


@cli.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False))
@click.option("-o", "--output", default="render.png", show_default=True,
              help="Output: an image, .png (sRGB 8-bit) or .exr (linear float); a numbered "
                   "sequence, out_####.png (the run of # becomes the frame number); or a "
                   "video, .mp4 (H.264) or .gif.")
@click.option("--pipeline", type=click.Choice(sorted(PIPELINES)), default=Pipeline.DEFERRED.value,
              show_default=True)
@click.option("--size", help="WIDTHxHEIGHT, overrides the scene's size.")
@click.option("--frames", type=click.IntRange(min=1, max=100_000), default=1, show_default=True,
              help="Render this many frames, frame i at --time + i / --fps seconds, to a "
                   "numbered sequence (a # pattern) or a video: one image holds one frame.")
@click.option("--fps", type=FiniteFloat(min=0.0, min_open=True, max=1000.0), default=24.0,
              show_default=True, help="Frames per second: the time step and the video's rate.")
@click.option("--time", "start_time", type=FiniteFloat(min=0.0, max=1e6), default=0.0,
              show_default=True, metavar="SECONDS",
              help="Time of the first frame (the scene's [[event]] timeline, animated "
                   "materials).")
@click.option("--turntable", type=click.IntRange(min=1, max=100_000), metavar="N",
              help="Orbit the camera once about the vertical through its target over N frames "
                   "(the times --frames N gives; frame N would be frame 0 again), to a # "
                   "pattern or a video.")
@click.option("--samples", type=click.IntRange(min=1, max=1024), default=1, show_default=True,
              help="Average each frame over this many renders moved by sub-pixel offsets "
                   "(Halton 2, 3), in linear light: anti-aliasing that converges to a "
                   "supersampled frame.")
@click.option("--light-path", type=LIGHT_PATH_CHOICE, help=LIGHT_PATH_HELP)
@click.option("--strict", is_flag=True,
              help="Fail on a uniform set by name that its program does not declare.")
@click.option("--view", "view_name", metavar="BUFFER",
              help="Write one buffer instead of the final image: albedo, normal, depth, "
                   "specular, material, shading, light, composite, a target, a pass (PASS or "
                   "PASS:TARGET) or a material's debug view (MATERIAL.VIEW, e.g. "
                   "revie_fur.samples). '--view help' lists them.")
def render(scene: str | None, output: str, pipeline: str, size: str | None, frames: int,
           fps: float, start_time: float, turntable: int | None, samples: int,
           light_path: str | None, strict: bool, view_name: str | None) -> None:
    """Render SCENE (a TOML file; the built-in demo when omitted) to an image, a numbered
    image sequence or a video."""
    from deferred.debug.capture import capture_frame
    from deferred.debug.views import (
        check_material_view,
        resolve_view,
        view,
        view_catalogue,
        with_material_view,
        write_view,
    )
    from deferred.io.paths import output_kind
    from deferred.io.video import (
        check_animation_memory,
        check_video_size,
        check_video_writer,
        frame_times,
    )
    from deferred.lighting.paths import resolve_light_path
    from deferred.render.renderer import FULL_FEATURES, Renderer
    from deferred.render.temporal import temporal_effect

    if view_name == "help":
        loaded = _scene(scene)
        passes = PIPELINES[pipeline](
            resolve_light_path(pipeline, light_path or loaded.light_path, FULL_FEATURES)
        ).passes(loaded)
        for name, doc in view_catalogue(passes, loaded):
            click.echo(f"{name:<36} {doc}")
        return
    out = check_output_path(output)
    kind = output_kind(out)
    if turntable is not None:
        source = click.get_current_context().get_parameter_source("frames")
        if source != click.core.ParameterSource.DEFAULT and frames != turntable:
            raise InputError(f"--turntable {turntable} renders {turntable} frames; leave "
                             "--frames out", "--frames")
        if kind == "image":
            raise InputError(f"a turntable is {turntable} frames and {out.name} holds one "
                             f"image: use a # pattern such as {out.stem}_####{out.suffix}, or "
                             ".mp4/.gif", "--turntable")
        frames = turntable
    times = frame_times(frames, fps, start_time)
    if view_name is not None and kind != "image":
        raise InputError("writes one buffer to one .png or .exr image, not to a frame "
                         "pattern or a video", "--view")
    if view_name is not None and samples > 1:
        raise InputError("--view shows one buffer of one render; --samples averages frames",
                         "--samples")
    if view_name is not None and frames > 1:
        raise InputError("--view writes one buffer of one frame; pick the frame with --time",
                         "--frames")
    if kind == "image" and frames > 1:
        raise InputError(f"{frames} frames cannot go to one image, {out.name}: use a # pattern "
                         f"such as {out.stem}_####{out.suffix}, or .mp4/.gif", "--frames")
    if kind == "video":
        check_video_writer(out)  # a missing extra is said before the scene loads
    with Progress("render", stderr) as progress:
        progress.status(f"loading {scene or 'the demo scene'} (meshes, UV unwraps)")
        loaded = _scene(scene)
        if turntable is not None:
            loaded.set_turntable(turntable / fps, start_time)
        _check_not_inputs(_render_outputs(out, kind, frames), loaded, scene, "-o")
        size_override = _size_option(size)
        if kind == "video":
            check_video_size(out, size_override or loaded.size)
            check_animation_memory(out, size_override or loaded.size, frames)
        shown_name = view_name
        if view_name is not None:
            debug_scene = with_material_view(loaded, view_name)
            if debug_scene is not None:  # the material draws the view: the frame shows it
                check_material_view(loaded, view_name, pipeline)
                loaded, view_name = debug_scene, None
        progress.status("starting the renderer")
        with Renderer(loaded, pipeline, size_override, strict=strict or None,
                      light_path=light_path) as renderer:
            renderer.check_times(times)  # a simulation cannot reach the last frame: refuse now
            if kind == "video":  # the frames a GIF holds with what the renderer holds
                check_animation_memory(out, renderer.size, frames,
                                       renderer_bytes=renderer.memory_bytes())
            if kind != "image":
                written, frame_ms = _render_animation(renderer, out, times, fps, progress,
                                                      samples)
            else:
                if view_name is not None:
                    view_pass, _ = resolve_view(view_name, renderer.passes)  # bad names fail
                progress.status("rendering the frame (shaders compile, simulations settle)")
                start = time.perf_counter()
                if view_name is not None:
                    if temporal_effect(loaded) is not None and times[0] >= 1.0 / fps:
                        # the frame before, so a temporal effect's buffers (the motion
                        # vectors, the history) show this frame's motion from it
                        renderer.render(readback=False, time=times[0] - 1.0 / fps)
                    capture = capture_frame(renderer, [view_pass] if view_pass else [],
                                            warmup=False, time=times[0])
                elif samples > 1:
                    result = renderer.render_samples(samples, times[0])
                else:
                    result = renderer.render(readback=True, time=times[0])
                renderer.gl.ctx.finish()
                frame_ms = [(time.perf_counter() - start) * 1000.0]
                # written while the renderer lives: the result may read its buffers lazily
                if view_name is not None:
                    write_view(out, view(capture, view_name))
                else:
                    _write_result(out, result)
                    result = None  # held past release, its HDR composite would be read back
    width, height = renderer.size
    timing = f"{min(frame_ms):.1f} ms" if frames == 1 else \
        f"median {sorted(frame_ms)[len(frame_ms) // 2]:.1f} ms over {frames} frames"
    shown = f", view {shown_name}" if shown_name is not None else ""
    clock = ""
    if frames > 1 or start_time > 0.0:
        clock = f", t = {times[0]:g}" + (f"..{times[-1]:g} s at {fps:g} fps" if frames > 1
                                         else " s")
    what = out if kind == "image" else written
    stderr.print(f"wrote {what} ({width}x{height}, {pipeline}, {renderer.light_path} lights"
                 f"{shown}{clock}, {timing})", markup=False, highlight=False)


def _render_animation(renderer, out: Path, times: list[float], fps: float,
                      progress: Progress, samples: int = 1) -> tuple[str, list[float]]:
    """Every frame of ``times`` to the sequence or video ``out``, each averaged over
    ``samples`` sub-pixel renders: (what was written, the frame times in ms)."""
    from deferred.io.video import AnimationWriter, describe_written

    frame_ms = []
    with AnimationWriter(out, fps) as writer:
        progress.count(len(times), "frames", f"rendering {out.name}")
        for index, at in enumerate(times):
            start = time.perf_counter()
            if samples > 1:
                averaged = renderer.render_samples(samples, at)
                frame_ms.append((time.perf_counter() - start) * 1000.0)
                writer.write(averaged.hdr if writer.wants_hdr else averaged.image)
            else:
                renderer.render(readback=False, time=at)
                renderer.gl.ctx.finish()
                frame_ms.append((time.perf_counter() - start) * 1000.0)
                writer.write(renderer.read_hdr() if writer.wants_hdr else renderer.read_final())
            progress.advance(index + 1, f"rendering {out.name}")
        progress.status(f"writing {out.name}")
        written = writer.close()
    return describe_written(written), frame_ms


@cli.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False))
@click.option("-o", "--output", metavar="DIR",
              help="Dump folder (created if missing). With --compare: where difference images "
                   "go (default DIR_B-diff next to DIR_B).")
@click.option("--pipeline", type=click.Choice(sorted(PIPELINES)), default=Pipeline.DEFERRED.value,
              show_default=True)
@click.option("--size", help="WIDTHxHEIGHT, overrides the scene's size.")
@click.option("--passes", metavar="NAME,...",
              help="Write only these passes' buffers (names or globs such as 'ball.*'); every "
                   "pass still runs.")
@click.option("--pixel", metavar="X,Y",
              help="Print every pass that wrote this pixel (top-down coordinates) and what it "
                   "wrote; recorded in the manifest too.")
@click.option("--light-path", type=LIGHT_PATH_CHOICE, help=LIGHT_PATH_HELP)
@click.option("--strict", is_flag=True,
              help="Fail on a uniform set by name that its program does not declare.")
@click.option("--compare", nargs=2, type=click.Path(), metavar="DIR_A DIR_B",
              help="Compare two dumps: per-buffer max/mean differences and difference images. "
                   "Exit status as diff's: 0 the same, 1 they differ, 2 bad input.")
def dump(scene: str | None, output: str | None, pipeline: str, size: str | None,
         passes: str | None, pixel: str | None, light_path: str | None, strict: bool,
         compare: tuple[str, str] | None) -> None:
    """Write every buffer of every pass of one frame of SCENE as EXR, plus a contact sheet and
    a manifest.json (README.md, "Debugging a frame", lists the files).

    With --compare DIR_A DIR_B: print each buffer's max and mean difference, write difference
    images, and exit 0 when the dumps are the same, 1 when they differ (as diff does)."""
    from deferred.debug.capture import select_passes
    from deferred.debug.dump import dump_scene
    from deferred.debug.dump_folder import check_dump_folder, check_dump_inputs
    from deferred.debug.pixel_history import format_history, parse_pixel
    from deferred.io.safety import scene_inputs
    from deferred.render.renderer import Renderer

    if compare:
        if scene or passes or pixel or size:
            raise InputError("compares two dump folders; give no scene, --size, --passes or "
                             "--pixel with it", "--compare")
        if _compare(*compare, output):
            raise click.exceptions.Exit(1)  # as diff: the dumps differ
        return
    if not output:
        raise InputError("a dump needs an output folder", "-o")
    out_dir = check_dump_folder(output)  # not a folder of other files: a dump replaces it
    patterns = [p.strip() for p in passes.split(",") if p.strip()] if passes is not None else None
    if patterns == []:
        raise InputError("names no pass (give names or globs, or leave --passes out)", "--passes")
    with Progress("dump", stderr) as progress:
        progress.status(f"loading {scene or 'the demo scene'} (meshes, UV unwraps)")
        loaded = _scene(scene)
        check_dump_inputs(out_dir, scene_inputs(loaded, scene))
        progress.status("starting the renderer")
        with Renderer(loaded, pipeline, _size_option(size), strict=strict or None,
                      light_path=light_path) as renderer:
            chosen = select_passes(renderer.passes, patterns)  # bad input fails before any file
            where = parse_pixel(pixel, renderer.size) if pixel is not None else None
            progress.status("capturing the frame (shaders compile, simulations settle)")
            manifest, history = dump_scene(
                renderer, out_dir, patterns, where,
                scene_file=str(Path(scene).resolve()) if scene else None,
                progress=lambda name: progress.status(f"writing {name}"))
    if history is not None and where is not None:
        for line in format_history(history, *where, renderer.size):
            click.echo(line)
    width, height = renderer.size
    stderr.print(f"wrote {out_dir}/ ({width}x{height}, {pipeline}, {len(chosen)} of "
                 f"{len(manifest['passes'])} passes, frame {manifest['frame_ms']:.1f} ms)")


def _compare(first: str, second: str, output: str | None) -> bool:
    """Compare two dumps, print the table; whether they differ."""
    from deferred.debug.compare import compare_dumps

    b = Path(second).resolve()  # "." has no name to build the default from
    out = Path(output) if output else b.parent / f"{b.name}-diff"
    results = compare_dumps(first, second, out)
    console = Console()
    if not console.is_terminal:
        console = Console(width=160)  # pipes and files: do not squeeze the table to 80 columns
    table = Table(title=f"{first} vs {second}", title_justify="left")
    for column in ("buffer", "channels", "max", "mean", "pixels", "note"):
        table.add_column(column, no_wrap=True,
                         justify="left" if column in ("buffer", "note") else "right")
    for r in results:
        if r.problem:
            table.add_row(r.buffer, "", "", "", "", r.problem)
        else:
            table.add_row(r.buffer, str(len(r.channels)), f"{r.max:.6g}", f"{r.mean:.6g}",
                          str(r.pixels), "")
    console.print(table)
    differing = sum(1 for r in results if r.differs)
    stderr.print(f"{differing} of {len(results)} buffers differ; difference images in {out}/")
    return differing > 0


@cli.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False))
@click.option("--lights", default="1,16,64,256,1024", show_default=True, metavar="N,...",
              help="Extra point lights added to the scene's own, one sweep point each.")
@click.option("--shells", metavar="N,...",
              help="Shell counts for every object whose material has 'shells'. Default: the "
                   "scene's own (0 where no object has shells).")
@click.option("--size", help="WIDTHxHEIGHT, overrides the scene's size.")
@click.option("--runs", type=click.IntRange(min=1, max=10_000), default=10, show_default=True,
              help="Rounds per point: in each, its frames timed back to back for 100 ms (1 to "
                   "4 counted), then one with each pass timed and one of CPU time.")
@click.option("--warmup", type=click.IntRange(min=0, max=10_000), default=2, show_default=True,
              help="Untimed frames first (shader compilation, first uploads).")
@click.option("--pipelines", default="deferred,forward", show_default=True, metavar="NAME,...")
@click.option("--light-paths", default="all", show_default=True, metavar="PATH,...",
              help="Light paths to time: all (every path of each pipeline), or names: "
                   "volumes, tiled, clustered (deferred), naive, tiled (forward).")
@click.option("--interleave/--no-interleave", default=True, show_default=True,
              help="Time the points of a shell count together, their frames alternating (all "
                   "their renderers alive at once), or one after another (less memory).")
@click.option("--json", "json_path", metavar="FILE.json",
              help="Results as JSON ('-': to stdout, in place of the table).")
@click.option("--csv", "csv_path", metavar="FILE.csv", help="Results as CSV.")
@click.option("--plot", "plot_path", metavar="FILE.png",
              help="ms against light count (needs the plot extra: pip install "
                   "'deferred[plot]').")
def bench(scene: str | None, lights: str, shells: str | None, size: str | None, runs: int,
          warmup: int,
          pipelines: str, light_paths: str, interleave: bool, json_path: str | None,
          csv_path: str | None, plot_path: str | None) -> None:
    """Time SCENE (the built-in demo when omitted) in each pipeline over a sweep of light and
    shell counts. The table goes to stdout, progress and the sweep's size and time to stderr;
    benchmarks/README.md describes the method and the results."""
    from deferred import bench as benchmark

    # Every option is checked before the first frame: bad input never costs a sweep.
    sweep = benchmark.Sweep(lights=benchmark.parse_counts(lights, "--lights"),
                            shells=None if shells is None else
                            benchmark.parse_counts(shells, "--shells"),
                            pipelines=benchmark.parse_pipelines(pipelines),
                            light_paths=benchmark.parse_light_paths(light_paths),
                            size=_size_option(size), runs=runs, warmup=warmup,
                            interleave=interleave)
    writers = {"--json": benchmark.write_json, "--csv": benchmark.write_csv,
               "--plot": benchmark.write_plot}
    outputs = {}
    for where, path in (("--json", json_path), ("--csv", csv_path), ("--plot", plot_path)):
        if path is not None and not (where == "--json" and path == "-"):
            outputs[where] = benchmark.check_output(path, where)
    loaded = _scene(scene)
    for where, path in outputs.items():
        _check_not_inputs([path], loaded, scene, where)
    benchmark.check_sweep(loaded, sweep)
    if shells is not None and not benchmark.shell_objects(loaded):
        stderr.print(f"{loaded.source}: no object has a 'shells' parameter; shell sweep "
                     "skipped (shells 0)")
    stderr.print(f"bench: {benchmark.describe_sweep(loaded, sweep)}; time: estimating",
                 markup=False, highlight=False)
    with Progress("bench", stderr) as progress:
        progress.count(benchmark.sweep_runs(loaded, sweep), "runs", "starting")
        estimated = []

        def step(at: benchmark.SweepProgress) -> None:
            progress.advance(at.runs_done, at.description, at.seconds_left)
            if at.seconds_left is not None and not estimated:  # the first measured run
                estimated.append(at.seconds_left)
                progress.note(f"bench: about {duration(at.seconds_left)} left, from the "
                              "first warm-up and run")

        report = benchmark.run_bench(loaded, sweep, progress=step)
    # The table and the comparisons are the results: on stdout, unless the JSON is there.
    results = Console(stderr=json_path == "-")
    if not results.is_terminal:
        results = Console(stderr=json_path == "-", width=160)  # pipes: not 80 columns
    results.print(benchmark.results_table(report))
    for line in [*benchmark.crossovers(report), *benchmark.speedups(report),
                 *benchmark.growth(report)]:
        results.print(line, markup=False, highlight=False, soft_wrap=True)
    if json_path == "-":
        try:  # a full disk or a closed pipe shows here, not as a warning at exit
            click.echo(report.to_json(), nl=False)
            sys.stdout.flush()
        except OSError as exc:
            # what did not fit stays buffered: send it to nowhere, or the flush at exit fails
            # again and prints a traceback
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            raise RenderError(f"cannot write standard output: {exc.strerror or exc}") from exc
    for where, path in outputs.items():
        writers[where](report, path)
    if outputs:
        stderr.print(f"wrote {', '.join(str(path) for path in outputs.values())}")


@cli.command("view")
@click.argument("scene", required=False, type=click.Path(dir_okay=False))
@click.option("--pipeline", type=click.Choice(sorted(PIPELINES)), default=Pipeline.DEFERRED.value,
              show_default=True)
@click.option("--light-path", type=LIGHT_PATH_CHOICE, help=LIGHT_PATH_HELP)
@click.option("--size", help="WIDTHxHEIGHT of the frame, overrides the scene's size.")
@click.option("--time", "start_time", type=FiniteFloat(min=0.0, max=1e6), default=0.0,
              show_default=True, metavar="SECONDS", help="The timeline's time at start.")
@click.option("--view", "view_name", metavar="BUFFER",
              help="Show one buffer, as render --view names it ('--view help' lists them).")
@click.option("--split", type=click.Choice(sorted(PIPELINES)),
              help="Split view: this pipeline on the right of the frame.")
@click.option("--headless", is_flag=True,
              help="Draw the window offscreen once (panels included) to --screenshot and exit.")
@click.option("--screenshot", metavar="OUT.png", help="With --headless: the window's image.")
@click.option("--no-panels", is_flag=True, help="The frame alone, without the panels.")
@click.option("--reduce", type=click.IntRange(min=1, max=8),
              help="While the camera moves or a value drags, draw frames this many times "
                   "smaller in each direction (the full frame follows when input stops). "
                   "Default: adapts, 2 to 8, to keep interaction near 15 fps.")
def view_command(scene: str | None, pipeline: str, light_path: str | None, size: str | None,
                 start_time: float, view_name: str | None, split: str | None, headless: bool,
                 screenshot: str | None, no_panels: bool, reduce: int | None) -> None:
    """Interactive viewer of SCENE (the built-in demo when omitted): orbit camera, live
    parameters, buffer views, split deferred / forward, pixel inspector, timeline, hot reload
    of GLSL and scene files, screenshots and recordings (README.md, "The viewer")."""
    try:
        from deferred.viewer.app import ViewerOptions, run_headless, run_window
        from deferred.viewer.session import Session
    except ImportError as exc:
        raise InputError(f"needs the viewer extra (pip install 'deferred[viewer]'): {exc}",
                         "view") from None
    if view_name == "help":
        click.get_current_context().invoke(render, scene=scene, pipeline=pipeline,
                                           light_path=light_path, view_name="help")
        return
    if headless != (screenshot is not None):
        raise InputError("--headless draws one frame to --screenshot: give both or neither",
                         "--headless" if headless else "--screenshot")
    out = check_output_path(screenshot, "--screenshot", (".png",), patterns=False) \
        if screenshot else None
    session = Session(scene)
    if out is not None:
        _check_not_inputs([out], session.scene, scene, "--screenshot")
    options = ViewerOptions(pipeline=pipeline, light_path=light_path, size=_size_option(size),
                            time=start_time, view=view_name, split=split, reduce=reduce,
                            panels=not no_panels)
    if view_name is not None:
        _check_view_name(session.scene, view_name, pipeline, light_path)
    if out is None:
        run_window(session, options)
        return
    written = run_headless(session, options, out)
    stderr.print(f"wrote {written}", markup=False, highlight=False)


def _check_view_name(loaded, view_name: str, pipeline: str, light_path: str | None) -> None:
    """A buffer name is known before a window opens (``InputError`` naming --view)."""
    from deferred.debug.views import check_material_view, resolve_view, with_material_view
    from deferred.lighting.paths import resolve_light_path
    from deferred.render.renderer import FULL_FEATURES

    if with_material_view(loaded, view_name) is not None:
        check_material_view(loaded, view_name, pipeline)
        return
    passes = PIPELINES[pipeline](
        resolve_light_path(pipeline, light_path or loaded.light_path, FULL_FEATURES)
    ).passes(loaded)
    resolve_view(view_name, passes)


def _render_outputs(out: Path, kind: str, frames: int) -> list[Path]:
    """Every file ``render -o`` writes: a sequence's frames, or the one file."""
    if kind != "sequence":
        return [out]
    from deferred.io.paths import expand_pattern

    return [expand_pattern(out, index) for index in range(frames)]


def _check_not_inputs(outputs: list[Path], loaded, scene: str | None, where: str) -> None:
    """No output may replace a file the scene reads (the scene, a mesh, a texture)."""
    from deferred.io.safety import check_not_inputs, scene_inputs

    check_not_inputs(outputs, scene_inputs(loaded, scene), where)


def _write_result(out: Path, result) -> None:
    if out.suffix.lower() == ".exr":
        write_image(out, result.hdr, channels=("R", "G", "B", "A"))
    else:
        write_image(out, result.image)


@cli.command("params")
@click.argument("kind", required=False)
@click.argument("name", required=False)
@click.option("--json", "as_json", is_flag=True, help="The listing as JSON on stdout.")
def params_command(kind: str | None, name: str | None, as_json: bool) -> None:
    """List the parameters of every registered type: name, type, default, range, choices and
    description. KIND is material, light, effect or shading_model; NAME one type of it
    (`deferred params light point`). Plugins are listed too."""
    from deferred.interfaces.catalogue import catalogue

    _print_params(catalogue(kind, name), as_json)


@cli.command()
@click.option("--json", "as_json", is_flag=True, help="The listing as JSON on stdout.")
def materials(as_json: bool) -> None:
    """List registered materials and their parameters (`deferred params material`)."""
    from deferred.interfaces.catalogue import catalogue

    _print_params(catalogue("material"), as_json)


def _print_params(entries: list[dict], as_json: bool) -> None:
    """A rich table per type on a terminal; plain lines at full width to a pipe or a file
    (a table squeezed to 80 columns cuts cells and drops descriptions)."""
    import json

    from deferred.interfaces.catalogue import default_text, heading, plain_lines, range_text

    if as_json:
        click.echo(json.dumps(entries, indent=2))
        return
    console = Console(markup=False, highlight=False)
    if not console.is_terminal:
        click.echo("\n".join(plain_lines(entries)))
        return
    for entry in entries:
        title = heading(entry) + (f"\n{entry['summary']}" if entry["summary"] else "")
        table = Table(title=title, title_justify="left")
        table.add_column("parameter", no_wrap=True)
        for column in ("type", "default", "range"):
            table.add_column(column, overflow="fold")
        table.add_column("description", ratio=1, overflow="fold")
        for row in entry["params"]:
            table.add_row(row["name"], row["type"], default_text(row), range_text(row),
                          row["description"])
        console.print(table if entry["params"] else f"{title}\n  (no parameters)")


@cli.command()
@click.option("-o", "--output", metavar="FILE.json",
              help="Write the schema here (default: stdout).")
def schema(output: str | None) -> None:
    """Write the JSON Schema of scene files (draft-07), for an editor's completion and
    checks: each object's material selects its params, each light's and effect's type its
    parameters (registered plugins included)."""
    import json

    from deferred.io.images import write_text
    from deferred.scene.schema import scene_schema

    out = check_output_path(output, "-o", (".json",), patterns=False) if output else None
    text = json.dumps(scene_schema(), indent=2) + "\n"
    if out is None:
        click.echo(text, nl=False)
        return
    write_text(out, text)
    stderr.print(f"wrote {out}", markup=False, highlight=False)


@cli.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False))
def info(scene: str | None) -> None:
    """GL vendor, renderer, version, the optional features in use, and the G-buffer layout of
    SCENE (the built-in demo when omitted)."""
    from deferred.gl.context import create_context

    layout = _scene(scene).gbuffer_layout()  # bad input fails before GL start-up
    gl = create_context()
    try:
        console = Console(soft_wrap=True, markup=False)  # one line per entry; [..] is text
        console.print(f"gbuffer: {layout.bytes_per_pixel} bytes per pixel")
        for name, entry in layout.describe().items():
            channels = f"  [{' '.join(entry['channels'])}]" if "channels" in entry else ""
            console.print(f"  {name:<20} {entry['format']:<8} {entry['bytes_per_pixel']:>2} B  "
                          f"{entry['description']}{channels}")
        for key, value in gl.info.items():
            console.print(f"{key:>16}: {value}")
        for key, value in gl.features.names().items():
            console.print(f"{key:>16}: {'on' if value else 'off'}")
        for what, reg in (("lights", registry.lights), ("materials", registry.materials),
                          ("shading models", registry.shading_models),
                          ("effects", registry.effects)):
            console.print(f"{what:>16}: {', '.join(reg)}")
    finally:
        gl.release()


def main(argv: list[str] | None = None) -> int:
    # SIGTERM unwinds like Ctrl-C, through the finally blocks that remove temporary files.
    with termination_as_interrupt(), warnings.catch_warnings():
        warnings.showwarning = _show_warning
        try:
            code = _main(argv)
            if code < 128:  # not ended by a signal already (said so once)
                raise_if_stop_requested()  # a signal whose exception was lost (a __del__ ate it)
            return code
        except KeyboardInterrupt as exc:
            return _interrupted(exc)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A Python warning as one line, ``warning: ...``, without the source file and line."""
    click.echo(f"warning: {one_line(str(message))}", err=True)


def _interrupted(exc: KeyboardInterrupt) -> int:
    click.echo("interrupted" if interrupt_exit_code(exc) == 130 else "terminated", err=True)
    return interrupt_exit_code(exc)


def _main(argv: list[str] | None) -> int:
    if not (sys.argv[1:] if argv is None else argv):  # no command: the help, not an error
        click.echo(cli.get_help(cli.make_context("deferred", [], resilient_parsing=True)))
        return 0
    try:
        code = cli.main(args=argv, prog_name="deferred", standalone_mode=False)
        return code if isinstance(code, int) else 0  # click returns an Exit's code
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.exceptions.Abort as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # click turns Ctrl-C into Abort
            return _interrupted(exc.__cause__)
        stderr.print("aborted")
        return 1
    except click.ClickException as exc:
        _fail(f"error: {exc.format_message()}")
        return 2
    except InputError as exc:  # a line per problem (a scene file's are said at once)
        problems = exc.problems
        shown = [f"error: {_as_option(problem)}" for problem in problems[:MAX_PROBLEM_LINES]]
        if len(problems) > MAX_PROBLEM_LINES:
            shown.append(f"error: ... and {len(problems) - MAX_PROBLEM_LINES} more problems")
        _fail(*shown)
        return 2
    except (RenderError, ShaderError, DeferredError) as exc:
        _fail(f"render failed: {exc}")
        return 1
    except Exception as exc:  # noqa: BLE001 - the last line of defence of a CLI
        _fail(f"render failed: {type(exc).__name__}: {exc}")
        return 1


# The Python API names its arguments in errors; the command line's options carry them
PYTHON_ARGUMENTS = {"light_path": "--light-path", "pipeline": "--pipeline", "size": "--size",
                    "time": "--time"}


def _as_option(problem: InputError) -> str:
    """A problem as the command line says it: a Python argument by the option that set it."""
    option = PYTHON_ARGUMENTS.get(problem.where or "")
    return f"{option}: {problem.message}" if option else str(problem)


def _fail(*messages: str) -> None:
    if Options.debug:
        traceback.print_exc()
    # one line each, whatever a file name holds: a newline in one is shown as \n
    for message in messages:
        click.echo(one_line(message), err=True)


def entry() -> None:
    sys.exit(main())


if __name__ == "__main__":
    entry()
