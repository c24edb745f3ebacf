"""The one exception every volviz reader raises for bad input, the warnings of a doubtful or partial read, and the
warning for kept non-finite values."""
from __future__ import annotations

import os
from typing import Sequence, Union

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


#: the most choices a ``ChoiceWarning`` carries, and the longest choice (characters)
MAX_CHOICES = 1000
MAX_CHOICE_CHARS = 256


class ChoiceWarning(ReadWarning):
    """A file holds several things to show (arrays of an HDF5 or MATLAB file, series of a DICOM folder, orbitals of a
    cube file, levels of an OME-Zarr image) and the reader showed one: ``path`` the file, ``option`` the reader
    option that picks another, ``chosen`` its value for the one shown and ``choices`` the values it takes (the shown
    one among them; strings or integers, as the option takes them), with a ``labels`` entry each to show a person;
    the message says the same in words."""

    def __init__(self, message: str, path: PathLike = "", option: str = "", chosen: str | int = "",
                 choices: Sequence[str | int] = (), labels: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.path = os.fspath(path)
        self.option = str(option)
        self.chosen = _choice(chosen)
        self.choices = [_choice(c) for c in list(choices)[:MAX_CHOICES]]
        texts = [str(t)[:MAX_CHOICE_CHARS] for t in list(labels)[:MAX_CHOICES]]
        self.labels = texts if len(texts) == len(self.choices) else [str(c) for c in self.choices]

    def fields(self) -> dict[str, object]:
        """The structured part, as plain data (what the isolated reader sends beside the message)."""
        return {"path": self.path, "option": self.option, "chosen": self.chosen, "choices": list(self.choices),
                "labels": list(self.labels)}

    @classmethod
    def from_fields(cls, message: str, fields: object) -> "ChoiceWarning | None":
        """The warning again from ``fields`` (as ``fields`` made them; None when they are not of that form)."""
        if not isinstance(fields, dict):
            return None
        path, option, chosen, choices, labels = (fields.get(k) for k in ("path", "option", "chosen", "choices",
                                                                          "labels"))
        if not (isinstance(path, str) and isinstance(option, str) and option.isidentifier()
                and isinstance(chosen, (str, int)) and _is_choice(chosen) and isinstance(choices, list)
                and isinstance(labels, list) and all(_is_choice(c) for c in choices)
                and all(isinstance(t, str) for t in labels)):
            return None
        return cls(message, path, option, chosen, choices, labels)


def _is_choice(value: object) -> bool:
    return isinstance(value, str) or (isinstance(value, int) and not isinstance(value, bool))


def _choice(value: str | int) -> str | int:
    return value if isinstance(value, int) and not isinstance(value, bool) else str(value)[:MAX_CHOICE_CHARS]


class NonFiniteWarning(UserWarning):
    """Emitted when a reader was called with ``allow_nonfinite=True`` and the data holds NaN or Inf values."""


def bytes_and_size(n: int) -> str:
    """An exact byte count with its ``human_bytes`` size where that says something more: ``'500 bytes'``,
    ``'18047 bytes (18 KB)'`` (an error message names both the header's claim and the file's size)."""
    return f"{int(n)} bytes" if abs(int(n)) < 1000 else f"{int(n)} bytes ({human_bytes(n)})"


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
