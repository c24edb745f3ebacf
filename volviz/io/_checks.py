"""Checks every reader makes before it trusts a file: it exists, is a regular readable file, its size agrees
with what its header claims (checked BEFORE any allocation), dimensions are positive, and float data is finite."""
from __future__ import annotations

import errno
import os
import stat
import warnings
from pathlib import Path
from typing import Sequence

import numpy as np

from volviz.io.errors import NonFiniteWarning, PathLike, ReadError, bytes_and_size


HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"   # at the start of an HDF5 file (at 512 after a user block: MAT v7.3)


def is_hdf5(head: bytes) -> bool:
    return head.startswith(HDF5_SIGNATURE)


def check_file(path: PathLike) -> Path:
    """Return ``path`` as a Path after checking it names an existing, regular, readable file."""
    try:
        p = Path(os.fspath(path))
        st = p.stat()
    except FileNotFoundError:
        raise ReadError(p, "no such file") from None
    except PermissionError:
        raise ReadError(p, "permission denied (cannot look up the file)") from None
    except OSError as exc:
        raise ReadError(p, f"cannot access the file ({exc.strerror or exc})") from None
    except (ValueError, TypeError) as exc:  # embedded NUL byte, not a path at all
        raise ReadError(str(path)[:200], f"is not a valid file name ({exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ReadError(p, "is a directory, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise ReadError(p, f"is {path_kind(st.st_mode)}, not a regular file")
    return p


def path_kind(mode: int) -> str:
    """What a file mode (``os.stat(...).st_mode``) is, in words: ``"a FIFO (named pipe)"``, ``"a folder"`` ..."""
    for test, words in ((stat.S_ISREG, "a regular file"), (stat.S_ISDIR, "a folder"),
                        (stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                        (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                        (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return words
    return "not a regular file"


def describe_bytes(data: bytes | str) -> str:
    """Describe content for an error message without quoting it: ``"empty"``, ``"text"`` or ``"binary data"``.

    Messages never echo file contents (they may be binary, huge or private); they say what kind of content it is."""
    if not data:
        return "empty"
    sample = data[:4096].encode("utf-8", "replace") if isinstance(data, str) else data[:4096]
    try:
        text = sample.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(sample) - 3:  # not just a multi-byte character cut at the sample's end
            return "binary data"
        text = sample[:exc.start].decode("utf-8")
    controls = sum(1 for c in text if ord(c) < 32 and c not in "\t\n\r\f")
    return "binary data" if controls else "text"


def open_file(path: PathLike):
    """Open a checked file for binary reading; permission and OS errors become ReadError."""
    p = check_file(path)
    try:
        return open(p, "rb")
    except PermissionError:
        raise ReadError(p, "permission denied (the file is not readable)") from None
    except IsADirectoryError:  # pragma: no cover - raced with check_file
        raise ReadError(p, "is a directory, not a file") from None
    except OSError as exc:
        raise ReadError(p, f"cannot open the file ({exc.strerror or exc})") from None


def file_size(path: PathLike) -> int:
    return check_file(path).stat().st_size


def read_bytes(path: PathLike, limit: int | None = None) -> bytes:
    """The file's bytes (at most ``limit``), with every OS problem turned into a ReadError."""
    with open_file(path) as fh:
        try:
            return fh.read() if limit is None else fh.read(limit)
        except OSError as exc:
            if exc.errno == errno.EISDIR:  # pragma: no cover
                raise ReadError(path, "is a directory, not a file") from None
            raise ReadError(path, f"read failed ({exc.strerror or exc})") from None


def read_at(path: PathLike, offset: int, count: int) -> bytearray:
    """Exactly ``count`` bytes at ``offset`` into a writable buffer (call only after the size was checked)."""
    buf = bytearray(count)
    with open_file(path) as fh:
        try:
            fh.seek(offset)
            got = fh.readinto(buf)
        except OSError as exc:
            raise ReadError(path, f"read failed ({exc.strerror or exc})") from None
    if got != count:
        raise ReadError(path, f"file ended early: needed {count} bytes at offset {offset}, got {got}")
    return buf


def check_dims(path: PathLike, dims: Sequence[int], what: str = "dimensions") -> tuple[int, ...]:
    """Every dimension a positive integer, else ReadError."""
    try:
        out = tuple(int(d) for d in dims)
    except (TypeError, ValueError, OverflowError):
        raise ReadError(path, f"{what} {tuple(dims)!r} are not integers") from None
    if any(d <= 0 for d in out):
        raise ReadError(path, f"{what} {'x'.join(str(d) for d in out)} must all be positive")
    return out


def describe_dims(dims: Sequence[int]) -> str:
    return "x".join(str(int(d)) for d in dims)


def require_bytes(path: PathLike, needed: int, available: int, what: str) -> None:
    """Fail fast when the file holds fewer bytes than the header says (no allocation has happened yet)."""
    if needed > available:
        raise ReadError(path, f"{what} needs {bytes_and_size(needed)} but the file holds only "
                              f"{bytes_and_size(available)} there: the file is truncated or the "
                              f"header is wrong")


def check_finite(path: PathLike, values: np.ndarray, allow_nonfinite: bool = True, what: str = "data") -> int:
    """Count NaN/Inf in float data. Raise ReadError unless ``allow_nonfinite``; then warn with the count.

    Returns the number of non-finite values (0 for integer data).
    """
    if values.dtype.kind not in "fc":
        return 0
    finite = np.isfinite(values)
    if finite.all():
        return 0
    bad = int(values.size - np.count_nonzero(finite))
    n_nan = int(np.count_nonzero(np.isnan(values)))
    first = np.argwhere(~finite)[0] if values.ndim else ()
    message = (f"{what} holds {bad} non-finite values of {values.size} ({n_nan} NaN, {bad - n_nan} Inf; "
               f"first at index {tuple(int(i) for i in first)})")
    if not allow_nonfinite:
        raise ReadError(path, message + "; pass allow_nonfinite=True to keep them")
    warnings.warn(f"{os.fspath(path)}: {message}", NonFiniteWarning, stacklevel=3)
    return bad


def parse_int(path: PathLike, token: bytes | str, what: str) -> int:
    try:
        text = token.decode("ascii") if isinstance(token, bytes) else token
        return int(text.strip())
    except (ValueError, UnicodeDecodeError):
        raise ReadError(path, f"{what} is {describe_bytes(token)}, not an integer") from None


def parse_float(path: PathLike, token: bytes | str, what: str, positive: bool = False) -> float:
    try:
        text = token.decode("ascii") if isinstance(token, bytes) else token
        value = float(text.strip().replace("D", "E").replace("d", "e"))
    except (ValueError, UnicodeDecodeError):
        raise ReadError(path, f"{what} is {describe_bytes(token)}, not a number") from None
    if not np.isfinite(value):
        raise ReadError(path, f"{what} is {value}, not a finite number")
    if positive and value <= 0:
        raise ReadError(path, f"{what} must be positive, got {value}")
    return value
