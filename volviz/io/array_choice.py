"""Which array of a container file to show (HDF5 datasets, MATLAB variables): the one the reader option names, else
the largest of three or four dimensions (else of two), the others named in a ``ReadWarning``."""
from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np

from volviz.io.errors import PathLike, ReadError, ReadWarning

Found = Sequence[tuple[str, tuple[int, ...]]]   # (name, shape) of the numeric 2D to 4D arrays of a file


def describe(found: Found, limit: int = 10) -> str:
    """``name (AxBxC), ...`` of at most ``limit`` arrays, then how many more."""
    shown = [f"{name} ({'x'.join(map(str, shape))})" for name, shape in list(found)[:limit]]
    return ", ".join(shown) + (f" and {len(found) - limit} more" if len(found) > limit else "")


def choose_array(path: PathLike, found: Found, wanted: str | None, option: str, none: str) -> str:
    """The name to show among ``found``: ``wanted`` (ReadError listing the arrays when there is no such one), else
    the largest volume, warning of the others (``option=...`` picks one); ReadError ``none`` when nothing is found."""
    if wanted is not None:
        if not any(name == wanted for name, _ in found):
            raise ReadError(path, f"has no numeric 2D to 4D {option} {wanted!r}; its arrays are: "
                                  f"{describe(found) or 'none'}")
        return wanted
    volumes = [item for item in found if len(item[1]) >= 3] or list(found)
    if not volumes:
        raise ReadError(path, none)
    chosen = max(volumes, key=lambda item: int(np.prod(item[1], dtype=object)))
    others = [item for item in volumes if item != chosen]
    if others:
        warnings.warn(f"{path}: holds {len(volumes)} arrays; showing the largest, {describe([chosen])}. Others: "
                      f"{describe(others)} ({option}=... picks one)", ReadWarning, stacklevel=4)
    return chosen[0]
