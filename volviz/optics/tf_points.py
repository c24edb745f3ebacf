"""Control-point edits of a transfer function, as the app's TF editor makes them (``app/docks/tf_editor.py``: a
click adds a point, a drag moves it, a right-click removes it). The points are plain arrays (scalars ``(n,)``, colors
``(n, 3)``, extinction ``(n,)``), not a ``TransferFunction``: while a point is dragged they may momentarily not make
one (two points at one scalar), and the editor keeps the last valid function meanwhile.

- ``insert_point``: a new point at (s, ρ) takes the color the function has there, and goes after the first point and
  before the last one (the end points keep the range);
- ``moved_scalar``: an interior point moves between its neighbours (it keeps its order), an end point keeps its scalar
  (only its ρ moves);
- ``remove_point``: drops a point (the editor removes only while more than two are left, ``MIN_POINTS``)."""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["MIN_POINTS", "insert_point", "moved_scalar", "remove_point"]

MIN_POINTS = 2  # a transfer function has at least two control points


def insert_point(scalars: Any, colors: Any, extinction: Any, s: float,
                 rho: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """New arrays with a point at scalar ``s`` and extinction ``rho``, colored as the function is at ``s``
    (linear between the points, the end colors beyond them); returns them and the new point's index, at least 1
    and at most ``n - 1``."""
    scalars, colors, extinction = np.asarray(scalars), np.asarray(colors), np.asarray(extinction)
    i = int(np.searchsorted(scalars, s))
    i = min(max(i, 1), len(scalars) - 1)
    color = np.array([np.interp(s, scalars, colors[:, c]) for c in range(3)])
    return (np.insert(scalars, i, s), np.insert(colors, i, color, axis=0), np.insert(extinction, i, rho), i)


def moved_scalar(scalars: Any, index: int, s: float) -> float:
    """Where a drag to scalar ``s`` puts point ``index``: an interior point stays strictly between its neighbours
    (by 1e-9 of the range, at least 1e-9), an end point where it is."""
    scalars = np.asarray(scalars)
    if 0 < index < len(scalars) - 1:
        eps = 1e-9 * max(abs(scalars[-1] - scalars[0]), 1.0)
        return float(np.clip(s, scalars[index - 1] + eps, scalars[index + 1] - eps))
    return float(scalars[index])


def remove_point(scalars: Any, colors: Any, extinction: Any,
                 index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """New arrays without point ``index``."""
    return (np.delete(np.asarray(scalars), index), np.delete(np.asarray(colors), index, axis=0),
            np.delete(np.asarray(extinction), index))
