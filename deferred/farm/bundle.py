"""A scene by content: the scene file and every file it reads (meshes, textures, strands,
wetness masks, glTF buffers: :func:`deferred.io.safety.scene_inputs`), as bytes under their
paths relative to the folder that holds them all. Workers write the files into a folder of
their own and load the scene from there, so they need no shared file system; the digest of
the bytes is what a sequence's manifest records as "the scene".
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from deferred.errors import InputError
from deferred.io.safety import scene_inputs, strings_in

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10: the same parser, as a package
    import tomli as tomllib

BUILTIN = "builtin:"


@dataclass(frozen=True)
class SceneBundle:
    """The files of a scene (``files``: relative POSIX path -> bytes) and which one is the
    scene (``scene``: its relative path; ``None`` with ``builtin`` for a scene shipped with the
    package, the demo when that is ``None`` too)."""

    scene: str | None
    files: dict[str, bytes] = field(default_factory=dict)
    builtin: str | None = None

    @property
    def digest(self) -> str:
        """sha256 over every file's relative path and bytes (and the built-in's name)."""
        hasher = hashlib.sha256()
        hasher.update(f"{self.builtin}\0{self.scene}\0".encode())
        for name in sorted(self.files):
            data = self.files[name]
            hasher.update(f"{name}\0{len(data)}\0".encode())
            hasher.update(data)
        return hasher.hexdigest()

    @property
    def size(self) -> int:
        return sum(len(data) for data in self.files.values())


def bundle_scene(scene_file: str | None, loaded: Any) -> SceneBundle:
    """The bundle of ``scene_file`` (as ``deferred render`` names it) as ``loaded`` read it."""
    if scene_file is None or scene_file.startswith(BUILTIN):
        return SceneBundle(scene=None, builtin=scene_file)
    inputs = [Path(os.path.abspath(path)) for path in scene_inputs(loaded, scene_file)]
    scene_path = Path(os.path.abspath(scene_file))
    # a path that climbs out of the scene's folder and back in (../scenes/tex.png) must find
    # the same folders on a worker: the root holds every folder the scene's paths pass through
    anchor = scene_path.parent
    for _ in range(_climbs(scene_path)):
        anchor = anchor.parent
    root = Path(os.path.commonpath([anchor, *(path.parent for path in inputs)]))
    files = {}
    for path in inputs:
        try:
            files[path.relative_to(root).as_posix()] = path.read_bytes()
        except OSError as exc:
            raise InputError(f"cannot read {path} to send it to the workers: "
                             f"{exc.strerror or exc}", str(path)) from None
    return SceneBundle(scene=scene_path.relative_to(root).as_posix(), files=files)


def _climbs(scene_path: Path) -> int:
    """The most ``..`` a path in the scene file starts with."""
    try:
        data = tomllib.loads(scene_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):  # a glTF file, or one the loader read otherwise
        return 0
    most = 0
    for text in strings_in(data):
        parts = Path(text).parts
        most = max(most, next((n for n, part in enumerate(parts) if part != ".."), len(parts)))
    return most


class UnpackedScene:
    """A bundle's files written into a new temporary folder (removed by :meth:`remove`):
    :attr:`path` is what to load (``None``, or a ``builtin:`` name, for a built-in scene)."""

    def __init__(self, bundle: SceneBundle):
        self.folder = Path(tempfile.mkdtemp(prefix="deferred-scene-"))
        for name, data in bundle.files.items():
            target = self.folder.joinpath(*name.split("/"))
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        self.path = str(self.folder.joinpath(*bundle.scene.split("/"))) \
            if bundle.scene is not None else bundle.builtin

    def remove(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)
