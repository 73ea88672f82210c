"""The ``deferred`` command line (DESIGN.md, "Command line").

Exit codes: 0 success, 1 a failure while rendering, 2 bad input. Bad input is one line on stderr
naming the file/key and the problem; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import sys
import time
import traceback
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from . import registry
from .errors import DeferredError, InputError, RenderError, ShaderError
from .imageio import check_output_path, write_image
from .pipeline import PIPELINES
from .scene import load_scene, parse_size

stderr = Console(stderr=True)


class Options:
    debug = False


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
              help="Output image: .png (sRGB 8-bit) or .exr (linear float).")
@click.option("--pipeline", type=click.Choice(sorted(PIPELINES)), default="deferred",
              show_default=True)
@click.option("--size", help="WIDTHxHEIGHT, overrides the scene's size.")
@click.option("--frames", type=click.IntRange(min=1), default=1, show_default=True,
              help="Render this many frames (timing); the last one is written.")
def render(scene: str | None, output: str, pipeline: str, size: str | None, frames: int) -> None:
    """Render SCENE (a TOML file; the built-in demo when omitted) to an image."""
    from .renderer import Renderer

    out = check_output_path(output)
    loaded = _scene(scene)
    with Renderer(loaded, pipeline, _size_option(size)) as renderer:
        times = []
        for _ in range(frames):
            start = time.perf_counter()
            result = renderer.render()
            renderer.gl.ctx.finish()
            times.append((time.perf_counter() - start) * 1000.0)
    _write_result(out, result)
    width, height = renderer.size
    timing = f"{min(times):.1f} ms" if frames == 1 else \
        f"median {sorted(times)[len(times) // 2]:.1f} ms over {frames} frames"
    stderr.print(f"wrote {out} ({width}x{height}, {pipeline}, {timing})")


def _write_result(out: Path, result) -> None:
    if out.suffix.lower() == ".exr":
        write_image(out, result.hdr, channels=("R", "G", "B", "A"))
    else:
        write_image(out, result.image)


@cli.command()
def materials() -> None:
    """List registered materials and their parameters."""
    console = Console()
    for name, cls in registry.materials.items():
        table = Table(title=f"{name}  (id {cls.type_id}, {cls.__module__})", title_justify="left")
        for column in ("parameter", "type", "default", "range"):
            table.add_column(column, no_wrap=True)
        table.add_column("description")
        for row in cls.describe_params():
            table.add_row(row["name"], row["type"], repr(row["default"]), row["range"],
                          row["doc"])
        console.print(table)


@cli.command()
def info() -> None:
    """GL vendor, renderer, version and the optional features in use."""
    from .context import create_context
    from .gbuffer import bytes_per_pixel

    gl = create_context()
    try:
        console = Console()
        for key, value in gl.info.items():
            console.print(f"{key:>16}: {value}")
        for key, value in gl.features.names().items():
            console.print(f"{key:>16}: {'on' if value else 'off'}")
        console.print(f"{'gbuffer':>16}: {bytes_per_pixel()} bytes per pixel")
        console.print(f"{'lights':>16}: {', '.join(registry.lights)}")
        console.print(f"{'materials':>16}: {', '.join(registry.materials)}")
    finally:
        gl.release()


def main(argv: list[str] | None = None) -> int:
    try:
        cli.main(args=argv, prog_name="deferred", standalone_mode=False)
        return 0
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.exceptions.Abort:
        stderr.print("aborted")
        return 1
    except click.ClickException as exc:
        _fail(f"error: {exc.format_message()}")
        return 2
    except InputError as exc:
        _fail(f"error: {exc}")
        return 2
    except (RenderError, ShaderError, DeferredError) as exc:
        _fail(f"render failed: {exc}")
        return 1
    except Exception as exc:  # noqa: BLE001 - the last line of defence of a CLI
        _fail(f"render failed: {type(exc).__name__}: {exc}")
        return 1


def _fail(message: str) -> None:
    if Options.debug:
        traceback.print_exc()
    click.echo(message, err=True)


def entry() -> None:
    sys.exit(main())


if __name__ == "__main__":
    entry()
