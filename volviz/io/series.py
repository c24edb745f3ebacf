"""Numbered file series: ``Storm.pvm-t01..t21``, ``quarter.1..93``, given as a list, a glob or a printf pattern.

``lazy_series`` turns them into one TimeSeries whose frames are read lazily (frame 0 is read at once so that a
bad series fails fast).
"""
from __future__ import annotations

import glob
import os
import re
from pathlib import Path
from typing import Any, Callable, Sequence, cast

import numpy as np

from volviz.io.errors import PathLike, ReadError
from volviz.model import TimeSeries

_PRINTF = re.compile(r"%(0?)(\d*)d")
_LAST_NUMBER = re.compile(r"(\d+)(?!.*\d)")


def _number_of(path: str) -> int | None:
    m = _LAST_NUMBER.search(os.path.basename(path))
    return int(m.group(1)) if m else None


def expand_pattern(pattern: str | PathLike | Sequence[PathLike]) -> list[tuple[int | None, Path]]:
    """Resolve a list of paths, a glob (``Storm.pvm-t*``) or a printf pattern (``quarter.%d``) to
    ``[(number, path), ...]`` sorted by the number in the file name (natural order). ReadError if nothing matches."""
    if isinstance(pattern, (list, tuple)):
        if not pattern:
            raise ReadError("<empty list>", "no files given for the series")
        items = [(_number_of(os.fspath(p)), Path(os.fspath(p))) for p in pattern]
        return items
    text = os.fspath(cast("str | os.PathLike[str]", pattern))  # a sequence other than a list or tuple: TypeError
    if _PRINTF.search(text):
        directory, base = os.path.split(text)
        parts = _PRINTF.split(base)
        regex = ""
        for i in range(0, len(parts), 3):
            regex += re.escape(parts[i])
            if i + 2 < len(parts):
                regex += r"(\d+)"
        rx = re.compile(regex + r"\Z")
        try:
            names = os.listdir(directory or ".")
        except OSError as exc:
            raise ReadError(text, f"cannot list the directory of the pattern ({exc.strerror or exc})") from None
        items = []
        for name in names:
            m = rx.match(name)
            if m:
                items.append((int(m.group(1)), Path(directory or ".") / name))
    elif any(ch in text for ch in "*?["):
        items = [(_number_of(p), Path(p)) for p in glob.glob(text)]
    else:
        items = [(_number_of(text), Path(text))]
    if not items:
        raise ReadError(text, "no files match this pattern")
    items.sort(key=lambda t: (t[0] is None, t[0] if t[0] is not None else 0, str(t[1])))
    return items


def series_times(items: Sequence[tuple[int | None, object]]) -> list[float]:
    """The times of a series' members (``expand_pattern`` items): the numbers in their names when those increase
    strictly along the series (``t01`` -> 1.0), else 0, 1, 2..."""
    numbers = [n for n, _ in items]
    if all(n is not None for n in numbers) and all(a < b for a, b in zip(numbers, numbers[1:])):  # type: ignore
        return [float(n) for n in numbers]  # type: ignore[arg-type]
    return [float(i) for i in range(len(items))]


def member_time(pattern: str | PathLike, member: PathLike) -> float | None:
    """The time at which ``lazy_series(pattern, ...)`` shows the file ``member`` (None when it is not in the series)."""
    items = expand_pattern(pattern)
    target = os.path.realpath(os.fspath(member))
    for (_, path), t in zip(items, series_times(items)):
        if os.path.realpath(os.fspath(path)) == target:
            return t
    return None


def lazy_series(paths_or_pattern: str | PathLike | Sequence[PathLike], reader: Callable[..., object],
                times: Sequence[float] | None = None, **options) -> TimeSeries:
    """A TimeSeries of every file of a numbered series, read lazily with ``reader`` (``volviz.io.read_series`` passes
    ``volviz.io.read``: the reader is an argument, so this module stays below the one that reads any file).

    Globs and printf patterns are sorted by the number in the file name; an explicit list keeps its order. Times
    are those numbers when they increase strictly along the series (``t01`` -> 1.0), else 0, 1, 2...; ``times``
    overrides them. Frame 0 is read now; every later frame must have frame 0's kind and dimensions.
    """
    items = expand_pattern(paths_or_pattern)
    read_frame: Callable[..., Any] = reader  # frames of any kind, checked against frame 0 below
    paths = [p for _, p in items]
    if times is None:
        times = series_times(items)
    if len(times) != len(paths):
        raise ValueError(f"{len(times)} times given for {len(paths)} files")
    first = read_frame(paths[0], **options)
    if isinstance(first, TimeSeries):
        raise ReadError(paths[0], "is itself a time series; a series of series is not supported")

    def load(index: int):
        frame = read_frame(paths[index], **options)
        if type(frame) is not type(first) or frame.dimensions != first.dimensions:
            raise ReadError(paths[index], f"frame {index} is a {getattr(frame, 'kind', type(frame).__name__)} of "
                                          f"{frame.dimensions}, but frame 0 ({paths[0]}) is a {first.kind} of "
                                          f"{first.dimensions}")
        return frame

    frames: list = [first] + [None] * (len(paths) - 1)
    return TimeSeries(np.asarray(times, dtype=np.float64), frames, loader=load,
                      source=os.fspath(os.path.commonpath([str(p) for p in paths])) if len(paths) > 1
                             else str(paths[0]))
