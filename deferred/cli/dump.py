"""``deferred dump``: every buffer of every pass of one frame to a folder, or two such folders
compared (``--compare``)."""

from __future__ import annotations

from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from deferred.cli import options
from deferred.cli.options import parse_size_option, stderr
from deferred.errors import InputError
from deferred.io.progress import Progress
from deferred.scene.loader import load_scene


@click.command()
@options.scene_argument
@click.option("-o", "--output", metavar="DIR",
              help="Dump folder (created if missing). With --compare: where difference images "
                   "go (default DIR_B-diff next to DIR_B).")
@options.pipeline_option
@options.size_option()
@click.option("--passes", metavar="NAME,...",
              help="Write only these passes' buffers (names or globs such as 'ball.*'); every "
                   "pass still runs.")
@click.option("--pixel", metavar="X,Y",
              help="Print every pass that wrote this pixel (top-down coordinates) and what it "
                   "wrote; recorded in the manifest too.")
@options.light_path_option
@options.strict_option
@click.option("--compare", nargs=2, type=click.Path(), metavar="DIR_A DIR_B",
              help="Compare two dumps: per-buffer max/mean differences and difference images. "
                   "Exit status as diff's: 0 the same, 1 they differ, 2 bad input.")
def dump(scene: str | None, output: str | None, pipeline: str, size: str | None,
         passes: str | None, pixel: str | None, light_path: str | None, strict: bool,
         compare: tuple[str, str] | None) -> None:
    """Write every buffer of every pass of one frame of SCENE as EXR, plus a contact sheet and
    a manifest.json (docs/guide/dump.md lists the files).

    With --compare DIR_A DIR_B: print each buffer's max and mean difference, write difference
    images, and exit 0 when the dumps are the same, 1 when they differ (as diff does)."""
    if compare:
        if scene or passes or pixel or size:
            raise InputError("compares two dump folders; give no scene, --size, --passes or "
                             "--pixel with it", "--compare")
        if compare_dumps(*compare, output):
            raise click.exceptions.Exit(1)  # as diff: the dumps differ
        return
    if not output:
        raise InputError("a dump needs an output folder", "-o")
    options.check_light_path_option(pipeline, light_path)
    from deferred.debug.dump_folder import check_dump_folder

    out_dir = check_dump_folder(output)  # not a folder of other files: a dump replaces it
    write_dump(scene, out_dir, pipeline, size, _pass_patterns(passes), pixel, light_path, strict)


def _pass_patterns(passes: str | None) -> list[str] | None:
    """--passes as names or globs; ``None``: every pass."""
    patterns = [p.strip() for p in passes.split(",") if p.strip()] if passes is not None else None
    if patterns == []:
        raise InputError("names no pass (give names or globs, or leave --passes out)", "--passes")
    return patterns


def write_dump(scene: str | None, out_dir: Path, pipeline: str, size: str | None,
               patterns: list[str] | None, pixel: str | None, light_path: str | None,
               strict: bool) -> None:
    """Dump one frame of ``scene`` to ``out_dir``; print the pixel's history."""
    from deferred.debug.capture import select_passes
    from deferred.debug.dump import dump_scene
    from deferred.debug.dump_folder import check_dump_inputs
    from deferred.debug.pixel_history import format_history, parse_pixel
    from deferred.io.safety import scene_inputs
    from deferred.render.renderer import Renderer

    with Progress("dump", stderr) as progress:
        progress.status(f"loading {scene or 'the demo scene'} (meshes, UV unwraps)")
        loaded = load_scene(scene)
        check_dump_inputs(out_dir, scene_inputs(loaded, scene))
        progress.status("starting the renderer")
        with Renderer(loaded, pipeline, parse_size_option(size), strict=strict or None,
                      light_path=light_path) as renderer:
            light_path_ran = renderer.light_path
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
    stderr.print(f"wrote {out_dir}/ ({width}x{height}, {pipeline}, {light_path_ran} lights, "
                 f"{len(chosen)} of "
                 f"{len(manifest['passes'])} passes, frame {manifest['frame_ms']:.1f} ms); "
                 f"open {(out_dir / 'index.html').resolve()} in a browser", markup=False,
                 highlight=False, soft_wrap=True)


def compare_dumps(first: str, second: str, output: str | None) -> bool:
    """Compare two dumps, print the table; whether they differ."""
    from deferred.debug.compare import compare_dumps as compare

    b = Path(second).resolve()  # "." has no name to build the default from
    out = Path(output) if output else b.parent / f"{b.name}-diff"
    results = compare(first, second, out)
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
