"""``--view BUFFER``, as ``render`` (one buffer written instead of the final image) and ``view``
(one buffer shown) take it: the option, the listing ``--view help`` prints, the checks of a
name, and the capture of one buffer from a renderer."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import click

from deferred.cli.options import Command
from deferred.errors import InputError
from deferred.render.pipeline import PIPELINES
from deferred.scene.loader import load_scene

if TYPE_CHECKING:
    from deferred.core.passes import RenderPass
    from deferred.debug.capture import FrameCapture
    from deferred.render.renderer import Renderer
    from deferred.scene import Scene

LISTING = "help"  # --view help lists the names instead of showing a buffer
RENDER_HELP = ("Write one buffer instead of the final image: albedo, normal, depth, specular, "
               "material, shading, light, composite, a target, a pass (PASS or PASS:TARGET) or "
               "a material's debug view (MATERIAL.VIEW, e.g. revie_fur.samples). '--view help' "
               "lists them.")
VIEWER_HELP = "Show one buffer, as render --view names it ('--view help' lists them)."


def view_option(text: str) -> Callable[[Command], Command]:
    return click.option("--view", "view_name", metavar="BUFFER", help=text)


def pipeline_passes(loaded: Scene, pipeline: str, light_path: str | None) -> list[RenderPass]:
    """The passes of ``pipeline`` over ``loaded`` as a renderer would make them (the light
    path given, else the scene's, resolved for every optional GL feature)."""
    from deferred.lighting.paths import resolve_light_path
    from deferred.render.renderer import FULL_FEATURES

    return PIPELINES[pipeline](
        resolve_light_path(pipeline, light_path or loaded.light_path, FULL_FEATURES)
    ).passes(loaded)


def print_view_names(scene: str | None, pipeline: str, light_path: str | None) -> None:
    """``--view help``: each buffer name SCENE's frame has, and what it shows."""
    from deferred.debug.views import view_catalogue

    loaded = load_scene(scene)
    for name, doc in view_catalogue(pipeline_passes(loaded, pipeline, light_path), loaded):
        click.echo(f"{name:<36} {doc}")


def check_view_name(loaded: Scene, view_name: str, pipeline: str,
                    light_path: str | None) -> None:
    """A buffer name is known before a window opens (``InputError`` naming --view)."""
    from deferred.debug.views import check_material_view, resolve_view, with_material_view

    if with_material_view(loaded, view_name) is not None:
        check_material_view(loaded, view_name, pipeline)
        return
    resolve_view(view_name, pipeline_passes(loaded, pipeline, light_path))


def check_one_buffer(view_name: str | None, kind: str, samples: int, frames: int) -> None:
    """--view writes one buffer of one render of one frame to one image."""
    if view_name is None:
        return
    if kind != "image":
        raise InputError("writes one buffer to one .png or .exr image, not to a frame "
                         "pattern or a video", "--view")
    if samples > 1:
        raise InputError("--view shows one buffer of one render; --samples averages frames",
                         "--samples")
    if frames > 1:
        raise InputError("--view writes one buffer of one frame; pick the frame with --time",
                         "--frames")


def material_view(loaded: Scene, view_name: str | None,
                  pipeline: str) -> tuple[Scene, str | None]:
    """The scene to render for ``--view`` and the buffer to capture from it. A material's
    debug view (MATERIAL.VIEW) is drawn by the material into the final image: the scene is
    then the material's debug scene and no buffer is captured."""
    from deferred.debug.views import check_material_view, with_material_view

    if view_name is None:
        return loaded, None
    debug_scene = with_material_view(loaded, view_name)
    if debug_scene is None:
        return loaded, view_name
    check_material_view(loaded, view_name, pipeline)
    return debug_scene, None


def view_pass(renderer: Renderer, view_name: str) -> str | None:
    """The pass after which ``view_name`` is captured (``InputError`` for an unknown name)."""
    from deferred.debug.views import resolve_view

    captured_after, _ = resolve_view(view_name, renderer.passes)
    return captured_after


def capture_view(renderer: Renderer, loaded: Scene, captured_after: str | None, at: float,
                 fps: float) -> FrameCapture:
    """Render the frame at ``at`` and keep the buffers ``captured_after`` wrote."""
    from deferred.debug.capture import capture_frame
    from deferred.render.temporal import temporal_effect

    if temporal_effect(loaded) is not None and at >= 1.0 / fps:
        # the frame before, so a temporal effect's buffers (the motion vectors, the history)
        # show this frame's motion from it
        renderer.render(readback=False, time=at - 1.0 / fps)
    return capture_frame(renderer, [captured_after] if captured_after else [], warmup=False,
                         time=at)


def write_captured_view(out: Path, capture: FrameCapture, view_name: str) -> None:
    from deferred.debug.views import view, write_view

    write_view(out, view(capture, view_name))
