"""A dump folder as a whole: what in it is the dump's (everything else is the user's and is
kept), and how a new dump replaces an old one: written to a staging folder beside it, then
swapped in under a lock, so a reader never sees half a dump and an interrupted dump leaves the
old one as it was."""
from __future__ import annotations

import fcntl
import hashlib
import json
import os
import re
import secrets
import shutil
import stat
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from deferred.errors import InputError
from deferred.io.paths import NAME_MAX
from deferred.io.safety import raise_if_stop_requested, signals_deferred

# The files a dump writes at the top of its folder; with "passes/NN_<pass>.exr" (PASS_FILE),
# everything else in a dump folder is the user's and is kept.
DUMP_FILES = frozenset({"gbuffer.exr", "light.exr", "final.exr", "final.png", "contact.png",
                        "manifest.json", "index.html"})
PASS_FILE = re.compile(r"\d+_.+\.exr")


def is_dump_folder(directory: str | Path) -> bool:
    """Whether ``directory`` holds a dump: a manifest of the dump format (written last)."""
    try:
        with open(Path(directory) / "manifest.json", encoding="utf-8") as handle:
            manifest = json.load(handle)
    except (OSError, ValueError):
        return False
    return isinstance(manifest, dict) and \
        str(manifest.get("format", "")).startswith("deferred-dump/")


def check_dump_folder(directory: str | Path, where: str = "-o") -> Path:
    """A folder a dump may replace: missing, empty, or an earlier dump. Anything else is
    refused (``InputError``) before any work: a dump replaces its folder as a whole, and a
    folder of other files is not a dump's to replace."""
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise InputError("exists and is not a folder", str(directory))
    if directory.is_dir() and not is_dump_folder(directory):
        try:
            empty = next(os.scandir(directory), None) is None
        except OSError as exc:
            raise InputError(f"cannot read the folder: {exc.strerror}", str(directory)) \
                from None
        if not empty:
            raise InputError(f"{directory} is not empty and holds no dump (no manifest.json); "
                             "give a new or empty folder, or an earlier dump", where)
    return directory


def is_dump_file(relative: str) -> bool:
    """Whether a path inside a dump folder (``passes/03_x.exr``) is one a dump writes."""
    parts = Path(relative).parts
    return (len(parts) == 1 and parts[0] in DUMP_FILES) or \
        (len(parts) == 2 and parts[0] == "passes" and PASS_FILE.fullmatch(parts[1]) is not None)


def check_dump_inputs(directory: str | Path, inputs: Sequence[Path], where: str = "-o") -> None:
    """``InputError`` when a file the scene reads (``inputs``) is one the dump into
    ``directory`` would replace (its ``final.png`` used as a texture, say)."""
    folder = Path(directory).resolve()
    for source in inputs:
        resolved = source.resolve()
        if folder in resolved.parents and is_dump_file(resolved.relative_to(folder).as_posix()):
            raise InputError(f"would overwrite {source}, a file the scene reads", where)


def _sibling(directory: Path, tag: str) -> Path:
    """A hidden name next to ``directory``: ``.<name>.<tag>``, the name cut (with a hash) where
    it would take the result past NAME_MAX bytes."""
    name = directory.name
    if len(name.encode()) > NAME_MAX - 40:
        digest = hashlib.sha1(name.encode()).hexdigest()[:8]
        name = name.encode()[:NAME_MAX - 60].decode(errors="ignore") + "-" + digest
    return directory.parent / f".{name}.{tag}"


def _stale_siblings(directory: Path) -> list[Path]:
    """Staging and replaced folders of dumps into ``directory`` that were killed (SIGKILL,
    power loss) before they could remove them; only safe to touch under the folder's lock."""
    prefixes = (_sibling(directory, "dump-").name, _sibling(directory, "old-").name)
    try:
        return sorted(entry for entry in directory.parent.iterdir()
                      if entry.name.startswith(prefixes))
    except OSError:
        return []


@contextmanager
def _folder_lock(directory: Path) -> Iterator[None]:
    """An exclusive ``flock`` on ``.<name>.lock`` next to ``directory``: dumps into one folder
    take turns. The lock file is removed on release; a waiter that then holds a lock on the
    removed file sees that its inode is no longer the path's and tries again."""
    path = _sibling(directory, "lock")
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            try:
                current = os.stat(path)
            except FileNotFoundError:
                current = None
            mine = os.fstat(fd)
            if current is not None and (current.st_ino, current.st_dev) == \
                    (mine.st_ino, mine.st_dev):
                break
        except BaseException:
            os.close(fd)
            raise
        os.close(fd)
    try:
        yield
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
        os.close(fd)


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        try:
            path.unlink()
        except OSError:
            pass


def _recover(directory: Path) -> None:
    """Under the lock: put back a dump whose replacement was killed between its two renames,
    then remove what killed dumps left next to the folder."""
    stale = _stale_siblings(directory)
    if not os.path.lexists(directory):
        replaced = [p for p in stale if p.name.startswith(_sibling(directory, "old-").name)]
        if replaced:
            os.rename(replaced[0], directory)
            stale.remove(replaced[0])
    for path in stale:
        _remove(path)


def _link_or_copy(source: str, target: str) -> None:
    try:
        os.link(source, target)
    except OSError:
        shutil.copy2(source, target)


def carry_over(old: Path, new: Path, own: Callable[[str], bool] = is_dump_file,
               prefix: str = "") -> bool:
    """Files in the old folder that are not the writer's ``own`` (by path relative to the
    folder; a dump's by default: :func:`is_dump_file`) go into the new one, the user's notes
    or a scene: hard links where the file system has them, so the old folder keeps its copy
    until the swap and an interrupted write loses nothing. Folders are merged with what the
    new one holds (a dump's ``passes/``). Whether any of the writer's own files was left out
    (a folder that held only those is not made again)."""
    skipped = False
    for entry in old.iterdir():
        relative = f"{prefix}{entry.name}"
        if own(relative):
            skipped = True
            continue
        target = new / entry.name
        if entry.is_dir() and not entry.is_symlink():
            made = not os.path.lexists(target)
            if made:
                target.mkdir()
            if target.is_dir() and not target.is_symlink():
                inner = carry_over(entry, target, own, f"{relative}/")
                skipped |= inner
                if made and inner and not any(target.iterdir()):
                    target.rmdir()  # it held the writer's files only
            continue
        _carry(entry, target)
    return skipped


def _carry(source: Path, target: Path) -> None:
    if os.path.lexists(target):
        return  # the new dump wrote this name
    if source.is_symlink():
        os.symlink(os.readlink(source), target)
    elif source.is_dir():
        shutil.copytree(source, target, symlinks=True, copy_function=_link_or_copy)
    else:
        _link_or_copy(str(source), str(target))


def swap_in_folder(staging: Path, directory: Path) -> None:
    """Replace ``directory`` with ``staging``: two renames with signals held between them, so
    the folder is always the old dump or the new one; then the old one is removed."""
    raise_if_stop_requested()  # a signal's exception lost on the way: the old folder stays
    old = _sibling(directory, f"old-{secrets.token_hex(4)}")
    with signals_deferred():
        had_old = os.path.lexists(directory)
        if had_old:
            os.rename(directory, old)
        try:
            os.rename(staging, directory)
        except BaseException:
            if had_old:
                os.rename(old, directory)
            raise
        if had_old:
            shutil.rmtree(old, ignore_errors=True)


@contextmanager
def staging_folder(directory: Path) -> Iterator[Path]:
    """Lock ``directory``, recover from killed dumps, and give a new hidden folder next to it to
    write the dump into; it is removed if the block fails (an error, Ctrl-C, SIGTERM)."""
    directory.parent.mkdir(parents=True, exist_ok=True)
    with _folder_lock(directory):
        _recover(directory)
        check_dump_folder(directory)  # again, under the lock: another dump may have run
        staging = _sibling(directory, f"dump-{secrets.token_hex(4)}")
        os.mkdir(staging)  # under the umask, not mkdtemp's 0700: it becomes the dump folder
        try:
            if directory.is_dir():
                os.chmod(staging, stat.S_IMODE(directory.stat().st_mode))
            (staging / "passes").mkdir()
            yield staging
        finally:
            if os.path.lexists(staging):
                with signals_deferred():
                    shutil.rmtree(staging, ignore_errors=True)
