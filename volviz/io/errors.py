"""The one exception every volviz reader raises for bad input, and the warning for kept non-finite values."""
from __future__ import annotations

import os
from typing import Union

PathLike = Union[str, "os.PathLike[str]"]


class ReadError(Exception):
    """A file could not be read as a dataset. The message always names the file and the problem.

    ``ReadError(path, "header claims 100000x100000x100000 voxels (1e15 bytes) but the file holds 18 KB")`` reads
    ``"<path>: header claims ..."``. The parts are kept as ``.path`` and ``.problem``; ``.advice`` (optional) says
    what to do instead, and follows the problem in the message.
    """

    def __init__(self, path: PathLike, problem: str, advice: str | None = None) -> None:
        self.path = os.fspath(path) if not isinstance(path, str) else path
        self.problem = str(problem)
        self.advice = advice          # what to do, when the reader knows better than "check the file"
        super().__init__(f"{self.path}: {self.problem}" + (f"; {advice}" if advice else ""))

    def __reduce__(self):  # picklable (background jobs send errors across threads)
        return (type(self), (self.path, self.problem, self.advice))


class ReadWarning(UserWarning):
    """A file was read, but something in it will likely be shown other than its author meant (a coordinate the reader
    takes for data, an orientation that is ignored): the message names the file and the doubt."""


class NonFiniteWarning(UserWarning):
    """Emitted when a reader was called with ``allow_nonfinite=True`` and the data holds NaN or Inf values."""


def human_bytes(n: int) -> str:
    """``18047`` -> ``'18 KB'``; exact for small sizes, one decimal otherwise."""
    value = float(n)
    for unit in ("bytes", "KB", "MB", "GB", "TB", "PB", "EB"):
        if abs(value) < 1000 or unit == "EB":
            if unit == "bytes":
                return f"{int(n)} bytes"
            return f"{value:.0f} {unit}" if value >= 10 else f"{value:.1f} {unit}"
        value /= 1000.0
    return f"{n} bytes"  # pragma: no cover
