"""The extent of a point set: the least and greatest coordinate on each axis.

numpy's ``points.min(axis=0)`` over an (n, 3) array reduces across rows, many times slower than reducing each column
on its own (measured in docs/bench/flow-gaps.md). Bounds are taken on the GUI thread when a scene is installed and
for each PT frame, so they use this.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt


def point_extent(points: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi): each column's least and greatest value of ``points`` (n, d), n > 0, as float64 arrays of d (NaN
    where a column holds NaN, as ``min(axis=0)`` gives)."""
    pts = np.asarray(points)
    if pts.ndim != 2 or not len(pts):
        raise ValueError(f"point_extent needs a non-empty (n, d) array, got shape {pts.shape}")
    columns = range(pts.shape[1])
    return (np.array([pts[:, c].min() for c in columns], dtype=np.float64),
            np.array([pts[:, c].max() for c in columns], dtype=np.float64))
