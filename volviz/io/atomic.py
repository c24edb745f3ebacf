"""Safe writes, shared by every writer in volviz (sessions, images, presets, series stores).

- Only regular files are replaced: :func:`check_output_path` refuses a device node, FIFO, socket, folder or symbolic
  link as a target, so ``-o /dev/null`` never replaces ``/dev/null`` even when run as root.
- A file is written to a temporary beside it, fsynced and renamed over the target: a reader never sees a half-written
  file, and the old file survives a failed write.
- Temporaries are named ``.NAME.volviz-tmp-PID-RANDOM``. A save killed between write and rename leaves one behind;
  the next save into that folder removes every such temporary whose process is gone, and the next save of the same
  target also those unchanged for :data:`STALE_AGE_S` (:func:`remove_stale_temporaries`).
- Two processes writing the same target each write their own temporary (unique name) and rename it: the target is
  always one complete file of one of them, never a mix.
- A directory store is replaced by :func:`replace_directory` so that a kill at any moment leaves one complete store
  (:func:`recover_directory` finishes or undoes an interrupted replacement).
"""
from __future__ import annotations

import os
import re
import secrets
import shutil
import stat
import time
from pathlib import Path

from volviz.io._checks import path_kind

__all__ = ["OutputPathError", "atomic_write_bytes", "atomic_write_text", "check_output_path", "new_temp_dir",
           "process_alive", "recover_directory", "remove_stale_temporaries", "replace_directory", "temp_name"]

_TEMP = re.compile(r"\A\.(?P<name>.+)\.volviz-(?P<role>tmp|old)-(?P<pid>\d+)-[0-9a-f]+\Z", re.S)


class OutputPathError(OSError):
    """A target that volviz will not replace (not a regular file) or cannot write into; names the path."""

    def __init__(self, path: str | os.PathLike, problem: str) -> None:
        self.path = os.fspath(path)
        self.problem = problem
        super().__init__(f"{self.path}: {problem}")

    def __str__(self) -> str:
        return f"{self.path}: {self.problem}"

    def __reduce__(self):  # picklable in its two-argument form (errors cross threads and processes)
        return (type(self), (self.path, self.problem))


def check_output_path(path: str | os.PathLike, directory: bool = False) -> Path:
    """Return ``path`` as a Path if volviz may write it: absent, or a regular file (a folder when ``directory``),
    in an existing folder. Anything else, a symbolic link included, raises :class:`OutputPathError`.

    Writers call this before writing; the CLI calls it up front so that a bad ``-o`` is a usage error."""
    p = Path(path)
    wanted = stat.S_ISDIR if directory else stat.S_ISREG
    try:
        mode = os.lstat(p).st_mode
    except FileNotFoundError:
        mode = None
    except (OSError, ValueError) as exc:
        raise OutputPathError(p, f"cannot be inspected ({getattr(exc, 'strerror', None) or exc})") from None
    if mode is not None and not wanted(mode):
        expected = "folders" if directory else "regular files"
        raise OutputPathError(p, f"is {path_kind(mode)}; volviz replaces only {expected}")
    parent = p.parent
    if not parent.is_dir():
        raise OutputPathError(p, f"the folder {parent} does not exist")
    return p


def temp_name(target: str | os.PathLike, role: str = "tmp") -> Path:
    """A fresh name beside ``target``: ``.NAME.volviz-ROLE-PID-RANDOM`` (``role`` is ``tmp`` or ``old``)."""
    t = Path(target)
    return t.with_name(f".{t.name}.volviz-{role}-{os.getpid()}-{secrets.token_hex(4)}")


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` is running (this process counts as running)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except PermissionError:  # a live process of another user
        return True
    except (ProcessLookupError, OverflowError):  # gone, or a number that cannot be a process id
        return False
    return pid > 0


#: seconds a temporary of the target being written may stay unchanged before it counts as abandoned even though a
#: process of its id runs (ids are reused after a kill, and a folder may be shared with another machine)
STALE_AGE_S = 30 * 60


def _abandoned(path: Path, now: float) -> bool:
    try:
        return now - os.lstat(path).st_mtime > STALE_AGE_S
    except OSError:
        return False


def _stale(folder: Path, name: str | None, role: str, target: str | None = None) -> list[Path]:
    """Leftovers of ``role`` in ``folder`` (of target ``name`` only, when given) whose writing process is gone, and
    those of target ``target`` unchanged for :data:`STALE_AGE_S` whatever their process id."""
    try:
        entries = os.listdir(folder)
    except OSError:
        return []
    found = []
    now = time.time()
    for entry in entries:
        m = _TEMP.match(entry)
        if m and m["role"] == role and (name is None or m["name"] == name) and (
                not process_alive(int(m["pid"])) or (m["name"] == target and _abandoned(folder / entry, now))):
            found.append(folder / entry)
    return found


def _remove(path: Path) -> None:
    try:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)
    except OSError:
        pass


def remove_stale_temporaries(folder: str | os.PathLike, target: str | os.PathLike | None = None) -> list[Path]:
    """Remove the temporaries (files and store folders) that interrupted saves left in ``folder``: every
    ``.NAME.volviz-tmp-PID-RANDOM`` whose process ``PID`` is no longer running, and those of the file ``target``
    about to be written that were not changed for :data:`STALE_AGE_S` (their id may belong to another process now).
    Returns what was removed."""
    removed = _stale(Path(folder), None, "tmp", None if target is None else Path(target).name)
    for path in removed:
        _remove(path)
    return removed


def _fsync_dir(folder: Path) -> None:
    try:  # make a rename durable
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError:
        pass


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write a file atomically: a temporary file in the same folder, fsync, rename; the old file survives a failure.
    Refuses targets that are not regular files (:func:`check_output_path`) and first removes stale temporaries of
    earlier interrupted saves in the folder."""
    target = check_output_path(path)
    remove_stale_temporaries(target.parent, target)
    tmp = temp_name(target)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # 0o666 & ~umask, as open() would
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        check_output_path(target)  # the target may have become something else while we wrote
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_dir(target.parent)


def atomic_write_text(path: str | os.PathLike, text: str, encoding: str = "utf-8") -> None:
    """``atomic_write_bytes`` of ``text`` encoded with ``encoding``."""
    atomic_write_bytes(path, text.encode(encoding))


# -- directory stores ------------------------------------------------------------------------------------------------
def recover_directory(path: str | os.PathLike) -> None:
    """Finish or undo a directory replacement that a killed process left half done, and remove its temporaries.

    :func:`replace_directory` moves the old store aside (``.NAME.volviz-old-PID-RANDOM``) before it renames the new
    one in. If only the aside copy exists, it is put back; if the store exists, leftover aside copies are deleted."""
    p = Path(path)
    asides = sorted(_stale(p.parent, p.name, "old"), key=lambda a: a.stat().st_mtime if a.exists() else 0.0)
    if asides and not os.path.lexists(p):
        try:
            os.rename(asides.pop(), p)  # the newest aside copy: the store as it was before the interrupted write
            _fsync_dir(p.parent)
        except OSError:
            return  # cannot repair here (read-only folder); the caller reports the missing store
    for aside in asides:
        _remove(aside)
    for tmp in _stale(p.parent, p.name, "tmp"):
        _remove(tmp)


def new_temp_dir(path: str | os.PathLike) -> Path:
    """Check that ``path`` may be replaced by a store folder, repair an interrupted replacement, and create the
    empty sibling folder to write the new store into (hand it to :func:`replace_directory` when complete)."""
    target = check_output_path(path, directory=True)
    recover_directory(target)
    remove_stale_temporaries(target.parent, target)
    tmp = temp_name(target)
    tmp.mkdir()
    return tmp


def replace_directory(tmp: str | os.PathLike, path: str | os.PathLike) -> None:
    """Put the complete store ``tmp`` in place of ``path`` so that a kill at any moment leaves one complete store:
    fsync the new files, rename the old store aside, rename the new one in, then delete the old one."""
    new, target = Path(tmp), check_output_path(path, directory=True)
    for entry in os.scandir(new):
        if entry.is_file(follow_symlinks=False):
            with open(entry.path, "rb") as handle:
                os.fsync(handle.fileno())
    _fsync_dir(new)
    aside = None
    if os.path.lexists(target):
        aside = temp_name(target, "old")
        os.rename(target, aside)
    os.rename(new, target)
    _fsync_dir(target.parent)
    if aside is not None:
        _remove(aside)
