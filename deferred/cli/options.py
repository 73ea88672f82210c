"""Arguments and options that several commands share, with the checks they make of a scene and
its outputs. Each is a decorator, so a command lists its options in the order ``--help`` shows
them."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

import click
from rich.console import Console

from deferred.errors import InputError
from deferred.io import safety
from deferred.names import LIGHT_PATHS, LightPath, Pipeline
from deferred.render.pipeline import PIPELINES
from deferred.scene.size import parse_size

if TYPE_CHECKING:
    from deferred.scene import Scene

stderr = Console(stderr=True, soft_wrap=True)  # status lines never wrap on pipes

Command = TypeVar("Command", bound=Callable)

LIGHT_PATH_CHOICE = click.Choice([path.value for path in LightPath])
LIGHT_PATH_HELP = ("How lights reach the pixels: volumes, tiled or clustered (deferred); naive or "
                   "tiled, i.e. Forward+ (forward). Default: the scene's light_path, else tiled "
                   "where compute shaders exist.")
SIZE_HELP = "WIDTHxHEIGHT, overrides the scene's size."


class FiniteFloat(click.FloatRange):
    """A float option within its range that is also finite (click takes "nan" and "inf")."""

    name = "finite float"

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


def scene_argument(command: Command) -> Command:
    """SCENE: a TOML file or a glTF file (.gltf, .glb); the built-in demo when omitted."""
    return click.argument("scene", required=False, type=click.Path(dir_okay=False))(command)


def gltf_options(command: Command) -> Command:
    """--camera and --animation: what a glTF SCENE shows."""
    command = click.option("--animation", metavar="NAME|INDEX",
                           help="A glTF SCENE's animation to play (default the first; "
                                "'none': none).")(command)
    return click.option("--camera", "gltf_camera", metavar="NAME",
                        help="A glTF SCENE's camera, by its name, its node's or its index "
                             "(default the first; without one, a camera framing the "
                             "scene).")(command)


def pipeline_option(command: Command) -> Command:
    return click.option("--pipeline", type=click.Choice(sorted(PIPELINES)),
                        default=Pipeline.DEFERRED.value, show_default=True)(command)


def size_option(text: str = SIZE_HELP) -> Callable[[Command], Command]:
    return click.option("--size", help=text)


def light_path_option(command: Command) -> Command:
    return click.option("--light-path", type=LIGHT_PATH_CHOICE, help=LIGHT_PATH_HELP)(command)


def check_light_path_option(pipeline: str, light_path: str | None) -> None:
    """--light-path names one of --pipeline's paths. (The Python API and a scene's
    ``light_path`` run the other pipeline's equivalent instead: the viewer switches pipelines
    under a chosen path, and a scene is rendered by both.)"""
    if light_path is None:
        return
    own = LIGHT_PATHS[Pipeline(pipeline)]
    if LightPath(light_path) not in own:
        other = next(p for p in Pipeline if LightPath(light_path) in LIGHT_PATHS[p])
        theirs = f"{', '.join(own[:-1])} and {own[-1]}"
        raise InputError(f"'{light_path}' is a light path of the {other} pipeline; the "
                         f"{pipeline} pipeline's are {theirs}", "--light-path")


def strict_option(command: Command) -> Command:
    return click.option("--strict", is_flag=True,
                        help="Fail on a uniform set by name that its program does not "
                             "declare.")(command)


def time_option(text: str) -> Callable[[Command], Command]:
    """--time SECONDS, the timeline's time (of the first frame)."""
    return click.option("--time", "start_time", type=FiniteFloat(min=0.0, max=1e6), default=0.0,
                        show_default=True, metavar="SECONDS", help=text)


def parse_size_option(value: str | None) -> tuple[int, int] | None:
    """--size as (width, height); ``None`` keeps the scene's size."""
    return None if value is None else parse_size(value)


def check_not_inputs(outputs: list[Path], loaded: Scene, scene: str | None, where: str) -> None:
    """No output may replace a file the scene reads (the scene, a mesh, a texture)."""
    safety.check_not_inputs(outputs, safety.scene_inputs(loaded, scene), where)
