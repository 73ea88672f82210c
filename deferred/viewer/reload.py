"""Hot reload: the GLSL files the renderers compile and the scene's own files, polled for
changes (a stat per file every ``POLL_SECONDS``: picked up within a second, no watcher thread
or extra dependency)."""

from __future__ import annotations

import time
from collections.abc import Iterable
from pathlib import Path

from deferred.gl.shaderlib import FrameworkShaders
from deferred.io.safety import scene_inputs
from deferred.scene.scene import Scene

POLL_SECONDS = 0.25
GLSL_SUFFIXES = (".glsl", ".vert", ".frag", ".geom", ".comp")


def shader_files(scene: Scene) -> list[Path]:
    """Every GLSL file the framework's shader folders and the scene's plugins' roots hold."""
    roots = [Path(str(folder)) for folder in FrameworkShaders().folders()]
    classes = [*(type(obj.material) for obj in scene.objects), *scene.light_types(),
               *scene.shading_models(), *(type(effect) for effect in scene.effects)]
    roots += [Path(str(cls.shader_root)) for cls in classes if cls.shader_root is not None]
    found: list[Path] = []
    for root in dict.fromkeys(roots):
        if root.is_dir():
            found += [p for p in root.rglob("*") if p.suffix in GLSL_SUFFIXES]
    return found


class Watcher:
    """Modification times of two sets of files, the shaders and the scene's."""

    def __init__(self, scene: Scene, scene_file: str | Path | None):
        self.scene_file = scene_file
        self.track(scene)
        self._last_poll = time.monotonic()

    def track(self, scene: Scene) -> None:
        """(Re)start from the files ``scene`` reads now."""
        self.shaders = _stamps(shader_files(scene))
        files = scene_inputs(scene, self.scene_file) if self.scene_file is not None else []
        self.scene_files = _stamps(files)

    def poll(self, force: bool = False) -> tuple[list[Path], list[Path]]:
        """(changed shader files, changed scene files) since the last poll; nothing until
        ``POLL_SECONDS`` have passed unless ``force``."""
        now = time.monotonic()
        if not force and now - self._last_poll < POLL_SECONDS:
            return [], []
        self._last_poll = now
        return _changed(self.shaders), _changed(self.scene_files)


def _stamp(path: Path) -> float | None:
    try:
        stat = path.stat()
    except OSError:
        return None
    return stat.st_mtime_ns + stat.st_size * 1e-3  # a same-second rewrite of another size


def _stamps(paths: Iterable[Path]) -> dict[Path, float | None]:
    return {path: _stamp(path) for path in paths}


def _changed(stamps: dict[Path, float | None]) -> list[Path]:
    changed = []
    for path, before in stamps.items():
        now = _stamp(path)
        if now != before:
            stamps[path] = now
            changed.append(path)
    return changed
