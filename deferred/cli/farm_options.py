"""``deferred render``'s options for rendering a sequence past one process: ``--workers N``,
``--ray [ADDRESS]`` and ``--resume`` (:mod:`deferred.farm`)."""

from __future__ import annotations

from collections.abc import Callable

import click

from deferred.errors import InputError
from deferred.io.extras import require_extra

RAY = "ray"


def farm_options(command: Callable) -> Callable:
    command = click.option(
        "--resume", is_flag=True,
        help="Skip the frames the manifest beside the sequence (OUT.manifest.jsonl) says are "
             "done, rendered from the same scene files, options and version; render the "
             "rest.")(command)
    command = click.option(
        "--ray", "ray", is_flag=False, flag_value="", default=None, metavar="[ADDRESS]",
        help="Render the frames on a Ray cluster (ray.init(address=ADDRESS); without an "
             "address a local Ray instance): one worker per GPU, else per node, or --workers "
             "N. Needs the ray extra.")(command)
    return click.option(
        "--workers", type=click.IntRange(min=1, max=256), metavar="N",
        help="Render the frames in N worker processes on this machine, each keeping a "
             "renderer warm over a chunk of frames; frames are byte-identical to one "
             "process's.")(command)


def check_farm_options(kind: str, workers: int | None, ray: str | None, resume: bool) -> None:
    """The options fit the output, and Ray is installed where asked for."""
    used = [name for name, value in (("--workers", workers), ("--ray", ray),
                                     ("--resume", resume or None)) if value is not None]
    if used and kind == "image":
        raise InputError("renders the frames of a sequence or a video (a # pattern, .mp4 or "
                         ".gif); one image is one frame", used[0])
    if ray is not None:
        require_extra(RAY, ("ray",), "--ray", "--ray")
