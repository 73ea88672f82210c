"""The manifest beside a frame sequence: what the frames were rendered from (the scene's
digest, the options, the version of deferred) and which frames are done, so ``--resume``
renders only the missing ones.

JSON lines: the first line is the header, then a line per finished frame (its number, file
name, byte count and sha256), appended and flushed as the frame is renamed into place. A run
killed at any moment leaves a readable manifest: a torn last line is ignored (that frame is
rendered again), and a frame is trusted only if its file still has the recorded bytes.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

from deferred.errors import InputError
from deferred.io.images import write_text

FORMAT = 1


def manifest_path(pattern: Path) -> Path:
    """``seq_####.png`` -> ``seq_####.manifest.jsonl`` beside it."""
    return pattern.with_suffix(".manifest.jsonl")


def manifest_header(scene_digest: str, options: dict[str, Any]) -> dict[str, Any]:
    from deferred import __version__

    return {"deferred_manifest": FORMAT, "version": __version__, "scene_sha256": scene_digest,
            "options": options}


def _differences(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    said = []
    if old.get("version") != new["version"]:
        said.append(f"deferred {old.get('version')} then, {new['version']} now")
    if old.get("scene_sha256") != new["scene_sha256"]:
        said.append("the scene or a file it reads changed")
    before, now = old.get("options") or {}, new["options"]
    said.extend(f"{key} was {before.get(key)!r}, now {now[key]!r}" for key in now
                if before.get(key) != now[key])
    return said


class Manifest:
    """The manifest at ``path``: opened fresh (the header written, earlier records gone) or,
    with ``resume``, read back (``InputError`` where its header differs from ``header``)."""

    def __init__(self, path: Path, header: dict[str, Any], resume: bool):
        self.path = path
        self.header = header
        self.records: dict[int, dict[str, Any]] = {}
        if resume and path.is_file():
            self._read()
        else:
            write_text(path, json.dumps(header, sort_keys=True) + "\n")
        self._file = open(path, "a", encoding="utf-8")  # noqa: SIM115 - closed by close()

    def _read(self) -> None:
        lines = self.path.read_text(encoding="utf-8", errors="replace").splitlines()
        try:
            old = json.loads(lines[0]) if lines else {}
        except ValueError:
            old = {}
        if not isinstance(old, dict) or old.get("deferred_manifest") != FORMAT:
            raise InputError(f"{self.path} is not a manifest deferred wrote: render without "
                             "--resume to start over", "--resume")
        differences = _differences(old, self.header)
        if differences:
            raise InputError(f"{self.path.name}: the frames were rendered from something else "
                             f"({'; '.join(differences)}): render without --resume to start "
                             "over", "--resume")
        for line in lines[1:]:
            try:
                record = json.loads(line)
                self.records[int(record["frame"])] = record
            except (ValueError, KeyError, TypeError):
                continue  # a line torn by a kill: its frame is rendered again

    def finished(self, index: int, file: Path, time: float) -> bool:
        """Whether frame ``index`` at ``time`` is recorded and ``file`` still holds its
        bytes."""
        record = self.records.get(index)
        if record is None or record.get("file") != file.name or record.get("time") != time:
            return False
        try:
            if file.stat().st_size != record.get("bytes"):
                return False
            return hashlib.sha256(file.read_bytes()).hexdigest() == record.get("sha256")
        except OSError:
            return False

    def record(self, index: int, file: Path, time: float, data: bytes) -> None:
        """Frame ``index`` at ``time`` is in place at ``file`` with ``data``."""
        record = {"frame": index, "time": time, "file": file.name, "bytes": len(data),
                  "sha256": hashlib.sha256(data).hexdigest()}
        self.records[index] = record
        self._file.write(json.dumps(record, sort_keys=True) + "\n")
        self._file.flush()  # a killed driver's OS still writes it: the frame is not lost

    def close(self) -> None:
        self._file.close()

    def remove(self) -> None:
        self.close()
        try:
            os.unlink(self.path)
        except OSError:
            pass
