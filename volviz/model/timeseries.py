"""Continuous display time over a time series (the libMini note's 4D interpolation): the data between two steps is
the linear blend of their point values (and of the point positions of a mesh that moves with one topology), so
playback is smooth at any display rate."""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Union, cast

import numpy as np

from volviz.model.datasets import CurvilinearGrid, Dataset, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh


def bracket(series: TimeSeries, t: float) -> tuple[int, int, float]:
    """Indices ``(i, j)`` of the steps around time ``t`` and the weight ``w`` of step ``j`` (t clamped to the span)."""
    times = series.times
    if t <= times[0]:
        return 0, 0, 0.0
    if t >= times[-1]:
        last = len(times) - 1
        return last, last, 0.0
    j = int(np.searchsorted(times, t, side="right"))
    i = j - 1
    return i, j, float((t - times[i]) / (times[j] - times[i]))


def _blend(a: np.ndarray, b: np.ndarray, w: float) -> np.ndarray:
    if a.shape != b.shape:
        raise ValueError(f"time steps differ in shape ({a.shape} and {b.shape}); cannot interpolate")
    return ((1.0 - w) * a.astype(np.float32) + w * b.astype(np.float32)).astype(np.float32)


def _moved_points(a: Any, b: Any, w: float) -> np.ndarray:
    """The points between two steps of a mesh: blended (float64) when the steps share one topology (the same cells,
    or the same grid) and the points moved, else the earlier step's."""
    if a.points.shape != b.points.shape or np.array_equal(a.points, b.points):
        return a.points
    if isinstance(a, TetMesh) and not np.array_equal(a.tets, b.tets):
        return a.points
    if isinstance(a, UnstructuredMesh) and (len(a.cells) != len(b.cells) or any(
            ta != tb or not np.array_equal(ca, cb) for (ta, ca), (tb, cb) in zip(a.cells, b.cells))):
        return a.points
    return (1.0 - w) * np.asarray(a.points, np.float64) + w * np.asarray(b.points, np.float64)


def frame_at(series: TimeSeries, t: float, interpolate: bool = True) -> Dataset:
    """The dataset shown at display time ``t``: the nearest earlier step, or the blend of its two neighbours (their
    point values, and the point positions of a mesh that moves with one topology). Between two steps of different
    sizes (an adaptively refined mesh, a regridded volume) there is no blend: the earlier step is shown."""
    i, j, w = bracket(series, t)
    if not interpolate or w == 0.0 or i == j:
        return series.frame(i)
    a, b = series.frame(i), series.frame(j)  # frames of one kind (read_series checks them against frame 0)
    if type(a) is not type(b) or a.dimensions != b.dimensions:
        return a
    if isinstance(a, RegularVolume):
        return replace(a, data=_blend(a.data, cast(RegularVolume, b).data, w))
    if isinstance(a, TetMesh):
        tb = cast(TetMesh, b)
        return TetMesh(_moved_points(a, tb, w), a.tets, _blend(a.scalars, tb.scalars, w), a.name, a.source)
    if isinstance(a, (CurvilinearGrid, UnstructuredMesh)):
        other = cast(Union[CurvilinearGrid, UnstructuredMesh], b)
        data = {name: _blend(arr, other.point_data[name], w) for name, arr in a.point_data.items()
                if name in other.point_data}
        return replace(a, points=_moved_points(a, other, w), point_data=data)
    raise ValueError(f"cannot interpolate a time series of {a.kind}")
