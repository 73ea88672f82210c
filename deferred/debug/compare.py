"""Comparing dumps (``deferred dump --compare``): two dump folders read back, buffers matched by
name (pass files by pass name) and channel, per-buffer max and mean absolute differences, and
difference images.
"""

from __future__ import annotations

import json
import re
import secrets
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from deferred.debug.dump import safe_name
from deferred.debug.dump_folder import DUMP_FILES, carry_over, swap_in_folder
from deferred.debug.preview import heat_colors, to_uint8
from deferred.errors import InputError, RenderError
from deferred.io.images import read_channels, write_image, write_text
from deferred.io.safety import same_file

COMPARE_FILE = "compare.json"  # marks a folder as a comparison's output
COMPARE_BAND_PIXELS = 1 << 20  # pixels compared at once
DIFFERENCE_PASS_IMAGE = re.compile(r"passes/[^/]+\.(exr|png)")


@dataclass
class BufferDiff:
    """Differences of one buffer between two dumps; ``problem`` says why it could not be
    compared (missing on one side, other size or channels)."""

    buffer: str
    channels: list[str] = field(default_factory=list)
    max: float = 0.0
    mean: float = 0.0
    pixels: int = 0  # pixels where any channel differs
    per_channel_max: dict[str, float] = field(default_factory=dict)
    problem: str | None = None
    image: str | None = None  # difference image written, relative to the output folder

    @property
    def differs(self) -> bool:
        """Whether the buffer differs between the dumps (or could not be compared): what
        ``dump --compare``'s exit status 1 says."""
        return self.problem is not None or self.max > 0.0 or self.pixels > 0

    def describe(self) -> dict[str, Any]:
        return {"buffer": self.buffer, "channels": self.channels, "max": self.max,
                "mean": self.mean, "pixels": self.pixels, "per_channel_max": self.per_channel_max,
                "problem": self.problem, "image": self.image}


def dump_buffers(directory: Path) -> dict[str, Path]:
    """Buffer key -> file of a dump folder; pass files are keyed by pass name, not number, so
    dumps whose pass lists differ still line up. The names come from the manifest where there
    is one: file names shorten long pass names."""
    if not directory.is_dir():
        raise InputError("not a folder", str(directory))
    found = {p.name: p for p in sorted(directory.glob("*.exr"))}
    named = _manifest_pass_files(directory)
    for path in sorted((directory / "passes").glob("*.exr")):
        found["passes/" + named.get(path.name, path.stem.split("_", 1)[-1])] = path
    if not found:
        raise InputError("no EXR buffers here: not a dump folder", str(directory))
    return found


def _manifest_pass_files(directory: Path) -> dict[str, str]:
    """File name -> pass name, from the dump's manifest (empty without one)."""
    try:
        manifest = json.loads((directory / "manifest.json").read_text(encoding="utf-8"))
        return {Path(entry["file"]).name: str(entry["name"]) for entry in manifest["passes"]
                if isinstance(entry.get("file"), str)}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


def check_compare_output(first: str | Path, second: str | Path, output: str | Path,
                         where: str = "-o") -> Path:
    """The folder for difference images must not be either dump or inside one: its files
    would replace the buffers being compared. ``InputError`` (exit 2) naming ``where``."""
    out = Path(output).resolve()
    for folder in (Path(first), Path(second)):
        inside = folder.resolve()
        if out == inside or inside in out.parents or same_file(out, inside):
            raise InputError(f"{output} is inside the dump {folder} being compared; "
                             "difference images would overwrite its files", where)
        if out in inside.parents:
            raise InputError(f"{output} holds the dump {folder} being compared; the "
                             "comparison replaces the folder as a whole", where)
    return Path(output)


def compare_dumps(first: str | Path, second: str | Path,
                  output: str | Path | None = None) -> list[BufferDiff]:
    """Per-buffer max/mean absolute differences of two dump folders, matched by channel name.

    Buffers that differ get a difference image in ``output``: ``<buffer>.exr`` with |B - A| per
    channel and ``<buffer>.png``, the largest channel difference scaled to the buffer's maximum
    (turbo; black where equal). NaN equals NaN; NaN against a number counts as infinite.
    """
    a_files, b_files = dump_buffers(Path(first)), dump_buffers(Path(second))
    if output is None:
        return _compare_all(a_files, b_files, first, second, None)
    out = check_compare_output(first, second, output).resolve()
    if out.exists() and not out.is_dir():
        raise InputError("exists and is not a folder", str(output))
    if out.is_dir() and any(out.iterdir()) and not (out / COMPARE_FILE).is_file():
        raise InputError("is a folder of other files, not an earlier comparison; choose an "
                         "empty or new folder", str(output))
    # Written as a whole: into a hidden folder next to the output, which then replaces it, so
    # an unreadable buffer or an interruption leaves no folder or the earlier comparison.
    staging = out.parent / f".{out.name[:200]}.compare-{secrets.token_hex(4)}"
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        staging.mkdir()
        results = _compare_all(a_files, b_files, first, second, staging)
        write_text(staging / COMPARE_FILE, json.dumps(
            {"a": str(first), "b": str(second), "buffers": [r.describe() for r in results]},
            indent=2) + "\n")
        if out.is_dir():  # an earlier comparison: the user's files in it stay
            carry_over(out, staging, _comparison_files(out))
        swap_in_folder(staging, out)  # the earlier comparison stays if the swap fails
    except OSError as exc:
        raise RenderError(f"cannot write {output}: {exc.strerror or exc}") from exc
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return results


def _comparison_files(folder: Path) -> Callable[[str], bool]:
    """Whether a path (relative to ``folder``, an earlier comparison) is one a comparison
    writes: its record, and difference images, by name (``gbuffer``, ``light``, ``final``,
    ``passes/*``, each ``.exr`` and ``.png``) and those the record names; every other file is
    the user's."""
    own = {COMPARE_FILE, *(f"{name.removesuffix('.exr')}.{kind}" for name in DUMP_FILES
                           if name.endswith(".exr") for kind in ("exr", "png"))}
    try:
        record = json.loads((folder / COMPARE_FILE).read_text(encoding="utf-8"))
        for entry in record.get("buffers", []):
            image = entry.get("image") if isinstance(entry, dict) else None
            if isinstance(image, str) and image.endswith(".exr"):
                own |= {image, f"{image.removesuffix('.exr')}.png"}
    except (OSError, ValueError, AttributeError, TypeError):
        pass  # an unreadable record: the names alone say which files are the comparison's
    return lambda relative: relative in own or DIFFERENCE_PASS_IMAGE.fullmatch(relative) is not None


def _compare_all(a_files: dict[str, Path], b_files: dict[str, Path], first: str | Path,
                 second: str | Path, out: Path | None) -> list[BufferDiff]:
    results = []
    for key in list(a_files) + [k for k in b_files if k not in a_files]:
        if key not in b_files or key not in a_files:
            side = Path(second if key not in b_files else first)
            results.append(BufferDiff(key, problem=f"missing in {side}"))
            continue
        results.append(_compare_buffer(key, a_files[key], b_files[key], out))
    return results


def _compare_buffer(key: str, path_a: Path, path_b: Path, out: Path | None) -> BufferDiff:
    a, names_a, _ = read_channels(path_a)
    b, names_b, _ = read_channels(path_b)
    if a.shape[:2] != b.shape[:2]:
        return BufferDiff(key, problem=f"size {a.shape[1]}x{a.shape[0]} vs "
                                       f"{b.shape[1]}x{b.shape[0]}")
    if sorted(names_a) != sorted(names_b):
        return BufferDiff(key, names_b, problem="channels differ: "
                          f"{' '.join(names_a)} vs {' '.join(names_b)}")
    order = [names_b.index(n) for n in names_a]
    height, width, count = a.shape
    # |B - A| into A's array, a band of rows at a time: two 8192^2 EXRs and their float
    # temporaries peaked at six times one of them
    diff = a
    rows = max(1, COMPARE_BAND_PIXELS // width)
    total = np.zeros(count)
    channel_max = np.zeros(count, np.float32)
    pixels = 0
    finite_peak = 0.0  # of the largest channel difference, for the heat image
    for first in range(0, height, rows):
        band_a, band_b = a[first:first + rows], b[first:first + rows][..., order]
        both_nan = np.isnan(band_a) & np.isnan(band_b)
        band = np.abs(band_b - band_a)
        band[np.isnan(band)] = np.inf  # NaN against a number
        band[both_nan] = 0.0
        diff[first:first + rows] = band
        total += band.sum(axis=(0, 1), dtype=np.float64)
        channel_max = np.maximum(channel_max, band.max(axis=(0, 1)))
        largest = band.max(axis=-1)
        pixels += int(np.count_nonzero(largest))
        finite = largest[np.isfinite(largest)]
        finite_peak = max(finite_peak, float(finite.max()) if finite.size else 0.0)
    del b
    result = BufferDiff(key, names_a, float(channel_max.max()),
                        float(total.sum() / max(diff.size, 1)), pixels,
                        {n: float(channel_max[k]) for k, n in enumerate(names_a)})
    if out is not None and result.max > 0.0:
        stem = _image_stem(key)
        (out / stem).parent.mkdir(parents=True, exist_ok=True)
        write_image(out / f"{stem}.exr", diff, channels=names_a)
        heat = np.empty((height, width, 3), np.uint8)
        for first in range(0, height, rows):
            heat[first:first + rows] = to_uint8(heat_colors(
                diff[first:first + rows].max(axis=-1), finite_peak))
        write_image(out / f"{stem}.png", heat)
        result.image = f"{stem}.exr"
    return result


def _image_stem(key: str) -> str:
    """The difference image's name for a buffer key: a pass name shortened as a dump shortens
    it (a 300-character object label must not make a file name too long)."""
    if key.startswith("passes/"):
        return "passes/" + safe_name(key.removeprefix("passes/"))
    return safe_name(key.removesuffix(".exr"))
