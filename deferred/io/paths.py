"""Output file names: what ``deferred render -o`` may write (images, numbered image sequences,
videos), checked before anything is rendered, and the hidden temporary name a file is written
under before it is renamed over the old one."""

from __future__ import annotations

import os
import re
import secrets
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

from deferred.errors import InputError

IMAGE_SUFFIXES = (".png", ".exr")
VIDEO_SUFFIXES = (".mp4", ".gif")
OUTPUT_SUFFIXES = (*IMAGE_SUFFIXES, *VIDEO_SUFFIXES)  # what ``deferred render -o`` writes
OutputKind = Literal["image", "sequence", "video"]
FRAME_RUN = re.compile(r"#+")
# A file name may hold 255 bytes on the common file systems (ext4, XFS, btrfs, APFS, NTFS).
NAME_MAX = 255
PATH_MAX = 4096  # bytes of a whole path (Linux)
# What temporary_path adds to a name: ".", ".", 12 hex digits, ".tmp".
_TEMPORARY_EXTRA = 18


def written_through(path: str | Path) -> Path:
    """The file a write to ``path`` replaces: ``path`` itself, or, where ``path`` is a
    symbolic link, the file it points to (an output is written through a link, which stays a
    link: the temporary file is made and renamed beside the target)."""
    path = Path(path)
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def temporary_path(path: str | Path) -> Path:
    """A hidden name next to ``path`` to write to before renaming over it; the suffix stays
    last so writers pick the format from it. The stem is shortened where the extra characters
    would take the name past ``NAME_MAX`` bytes (the random part keeps it unique)."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    stem = path.stem
    room = NAME_MAX - _TEMPORARY_EXTRA - len(path.suffix.encode())
    if len(stem.encode()) > room:
        stem = stem.encode()[:max(room, 1)].decode(errors="ignore")
    # Not mkstemp: its 0600 mode would survive the rename; the writer creates the file under
    # the umask like any other output.
    return directory / f".{stem}.{secrets.token_hex(6)}.tmp{path.suffix}"


def check_output_path(path: str | Path, where: str = "-o",
                      suffixes: tuple[str, ...] = OUTPUT_SUFFIXES,
                      patterns: bool = True) -> Path:
    """An output file named by option ``where``: one of ``suffixes``, in an existing folder,
    not itself a folder. With ``patterns``, a name with a run of ``#`` is a numbered image
    sequence (:func:`expand_pattern`), checked as its first file."""
    path = Path(path)
    shown = str(path) if len(str(path)) <= 120 else f"{str(path)[:60]}...{str(path)[-40:]}"
    if path.suffix.lower() not in suffixes:
        raise InputError(f"output must end in {_either(suffixes)}: {shown}", where)
    if any(len(part.encode()) > NAME_MAX for part in path.parent.parts):
        raise InputError(f"folder name longer than {NAME_MAX} bytes: {shown}", where)
    if len(path.name.encode()) > NAME_MAX:
        raise InputError(f"file name longer than {NAME_MAX} bytes: {path.name[:40]}...", where)
    if len(str(path.absolute()).encode()) >= PATH_MAX:
        raise InputError(f"path longer than {PATH_MAX} bytes: {shown}", where)
    if not path.parent.is_dir():
        raise InputError(f"output folder does not exist: {path.parent}", where)
    first = path
    if patterns and "#" in path.name:
        first = expand_pattern(path, 0, where)
    if len(first.name.encode()) > NAME_MAX:
        # caught here, not after the frame is rendered and written to a temporary name
        raise InputError(f"file name longer than {NAME_MAX} bytes: {first.name[:40]}...", where)
    if first.is_dir():
        raise InputError(f"output is a folder, not a file: {first}", where)
    target = written_through(first)
    if target != first and not target.parent.is_dir():
        raise InputError(f"output {first.name} is a symbolic link to {target}, whose folder "
                         "does not exist", where)
    return path


def _either(suffixes: Sequence[str]) -> str:
    return suffixes[0] if len(suffixes) == 1 else \
        f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"


# OpenEXR stores channels sorted by name; this attribute keeps the order they were written in.


def is_pattern(path: str | Path) -> bool:
    """Whether ``path``'s file name has a run of ``#`` (a numbered sequence)."""
    return "#" in Path(path).name


def expand_pattern(path: str | Path, index: int, where: str = "-o") -> Path:
    """``out_####.png``, 7 -> ``out_0007.png``: the file name's run of ``#`` becomes ``index``
    zero-padded to the run's length. A name must have exactly one run."""
    path = Path(path)
    runs = FRAME_RUN.findall(path.name)
    if len(runs) != 1:
        raise InputError(f"a frame pattern has one run of '#' (out_####.png), got {path.name}",
                         where)
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        raise InputError(f"a frame pattern must end in {' or '.join(IMAGE_SUFFIXES)}: {path}",
                         where)
    if index < 0:
        raise ValueError(f"frame number {index} < 0")
    width = len(runs[0])
    return path.with_name(FRAME_RUN.sub(f"{index:0{width}d}", path.name))


def output_kind(path: str | Path) -> OutputKind:
    """``"sequence"`` (a ``#`` pattern), ``"video"`` (.mp4, .gif) or ``"image"``."""
    if is_pattern(path):
        return "sequence"
    return "video" if Path(path).suffix.lower() in VIDEO_SUFFIXES else "image"
