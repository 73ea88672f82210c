"""The disk cache of things slow to make and made again the same from the same inputs (tonal
art maps, an environment light's prefiltered maps): where it lives and how a file enters it."""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from pathlib import Path

import numpy as np


def cache_folder() -> Path:
    """Where cached files live: ``$DEFERRED_CACHE_DIR``, else the user's cache folder
    (``$XDG_CACHE_HOME`` or ~/.cache on Linux) under ``deferred``."""
    folder = os.environ.get("DEFERRED_CACHE_DIR")
    if folder:
        return Path(folder)
    if sys.platform == "win32":
        local = os.environ.get("LOCALAPPDATA")
        return (Path(local) if local else Path.home() / "AppData" / "Local") / "deferred" / "Cache"
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "deferred"
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "deferred"


def file_digest(path: Path) -> str:
    """The SHA-256 of a file's bytes, in hex (read a megabyte at a time)."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def write_cached_arrays(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` to ``path`` (``.npz``) atomically: a temporary file in the same folder,
    renamed. A cache that cannot be written is skipped, not an error."""
    temporary = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path.parent, prefix=f".{path.stem}-",
                                         suffix=".tmp", delete=False) as handle:
            temporary = Path(handle.name)
            np.savez(handle, **arrays)
        os.replace(temporary, path)
        temporary = None
    except OSError:
        pass
    finally:
        if temporary is not None:
            temporary.unlink(missing_ok=True)
