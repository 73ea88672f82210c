"""The optional parts of the install (``pyproject.toml``'s extras): ``video`` (imageio and
imageio-ffmpeg, for ``.mp4``) and ``plot`` (matplotlib, for ``bench --plot``). A command that
needs a missing one says so in one line, naming the extra to install."""

from __future__ import annotations

import importlib

from deferred.errors import InputError

VIDEO = "video"
PLOT = "plot"


def require_extra(extra: str, modules: tuple[str, ...], what: str, where: str) -> None:
    """``InputError`` (``where: writing .mp4 needs the video extra: pip install
    'deferred[video]'``) unless every one of ``modules`` imports."""
    for module in modules:
        try:
            importlib.import_module(module)
        except ImportError:
            raise InputError(f"{what} needs the {extra} extra: pip install 'deferred[{extra}]'",
                             where) from None
