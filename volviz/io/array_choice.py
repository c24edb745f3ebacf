"""Which array of a container file to show (HDF5 datasets, MATLAB variables): the one the reader option names, else
the largest of three or four dimensions (else of two), the others named in a ``ChoiceWarning``."""
from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np

from volviz.io.errors import ChoiceWarning, PathLike, ReadError

Found = Sequence[tuple[str, tuple[int, ...]]]   # (name, shape) of the numeric 2D to 4D arrays of a file


def describe(found: Found, limit: int = 10) -> str:
    """``name (AxBxC), ...`` of at most ``limit`` arrays, then how many more."""
    shown = [f"{name} ({'x'.join(map(str, shape))})" for name, shape in list(found)[:limit]]
    return ", ".join(shown) + (f" and {len(found) - limit} more" if len(found) > limit else "")


def choose_array(path: PathLike, found: Found, wanted: str | None, option: str, none: str) -> str:
    """The name to show among ``found``: ``wanted`` (ReadError listing the arrays when there is no such one), else
    the largest volume; ReadError ``none`` when nothing is found. When there are others to show, a ``ChoiceWarning``
    names them (``option=...`` picks one) with the choices as data, for a chooser."""
    if wanted is not None and not any(name == wanted for name, _ in found):
        raise ReadError(path, f"has no numeric 2D to 4D {option} {wanted!r}; its arrays are: "
                              f"{describe(found) or 'none'}")
    volumes = [item for item in found if len(item[1]) >= 3] or list(found)
    if not volumes:
        raise ReadError(path, none)
    if wanted is not None:
        chosen = next(item for item in found if item[0] == wanted)
        volumes = volumes if chosen in volumes else [chosen] + volumes
    else:
        chosen = max(volumes, key=lambda item: int(np.prod(item[1], dtype=object)))
    others = [item for item in volumes if item != chosen]
    if others:
        how = "as asked" if wanted is not None else "the largest"
        warnings.warn(ChoiceWarning(f"{path}: holds {len(volumes)} arrays; showing {how}, {describe([chosen])}. "
                                    f"Others: {describe(others)} ({option}=... picks one)", path, option, chosen[0],
                                    [name for name, _ in volumes], [describe([item]) for item in volumes]),
                      stacklevel=4)
    return chosen[0]
