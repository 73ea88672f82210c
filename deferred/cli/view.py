"""``deferred view``: the interactive viewer (docs/guide/view.md), or its window drawn once
offscreen (``--headless``)."""

from __future__ import annotations

import click

from deferred.cli import options
from deferred.cli.options import (
    check_light_path_option,
    check_not_inputs,
    parse_size_option,
    stderr,
)
from deferred.cli.view_option import (
    LISTING,
    VIEWER_HELP,
    check_view_name,
    print_view_names,
    view_option,
)
from deferred.errors import InputError
from deferred.io.paths import check_output_path
from deferred.render.pipeline import PIPELINES


@click.command("view")
@options.scene_argument
@options.pipeline_option
@options.light_path_option
@options.size_option("WIDTHxHEIGHT of the frame, overrides the scene's size.")
@options.time_option("The timeline's time at start.")
@view_option(VIEWER_HELP)
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
    of GLSL and scene files, screenshots and recordings (docs/guide/view.md)."""
    try:
        from deferred.viewer.app import ViewerOptions
        from deferred.viewer.session import Session
        from deferred.viewer.window import run_headless, run_window
    except ImportError as exc:
        raise InputError(f"needs the viewer extra (pip install 'deferred[viewer]'): {exc}",
                         "view") from None
    check_light_path_option(pipeline, light_path)
    if view_name == LISTING:
        print_view_names(scene, pipeline, light_path)
        return
    if headless != (screenshot is not None):
        raise InputError("--headless draws one frame to --screenshot: give both or neither",
                         "--headless" if headless else "--screenshot")
    out = check_output_path(screenshot, "--screenshot", (".png",), patterns=False) \
        if screenshot else None
    session = Session(scene)
    if out is not None:
        check_not_inputs([out], session.scene, scene, "--screenshot")
    options = ViewerOptions(pipeline=pipeline, light_path=light_path,
                            size=parse_size_option(size), time=start_time, view=view_name,
                            split=split, reduce=reduce, panels=not no_panels)
    if view_name is not None:
        check_view_name(session.scene, view_name, pipeline, light_path)
    if out is None:
        run_window(session, options)
        return
    written = run_headless(session, options, out)
    stderr.print(f"wrote {written}", markup=False, highlight=False)
