"""Summary statistics of a dataset's active scalar: the values and their histogram
(for the transfer-function editor)."""
from __future__ import annotations

from typing import Union

import numpy as np

from volviz.model.datasets import (CurvilinearGrid, Dataset, Image2D, RegularVolume, TetMesh, TimeSeries,
                                   UnstructuredMesh)


MAX_SERIES_VALUES = 50_000_000


def scalar_values(dataset: Union[Dataset, TimeSeries]) -> np.ndarray:
    """The active scalar of a dataset as a flat array (vector arrays by their magnitude); for a time series, the
    values of all its steps (of evenly spaced steps when that would exceed ``MAX_SERIES_VALUES``)."""
    if isinstance(dataset, TimeSeries):
        n = len(dataset)
        step = max(1, (n * dataset.n_points) // MAX_SERIES_VALUES)  # every step while small, else every k-th
        return np.concatenate([scalar_values(dataset.frame(i)) for i in range(0, n, step)])
    if isinstance(dataset, (RegularVolume, Image2D)):
        values = dataset.data
    elif isinstance(dataset, TetMesh):
        values = dataset.scalars
    elif isinstance(dataset, (CurvilinearGrid, UnstructuredMesh)):
        if not dataset.active:
            return np.zeros(0)
        values = dataset.point_data[dataset.active]
        if isinstance(dataset, CurvilinearGrid) and values.ndim == 4 or isinstance(dataset, UnstructuredMesh) \
                and values.ndim == 2:
            values = np.linalg.norm(values, axis=-1)
    else:
        raise TypeError(f"no scalar values for {type(dataset).__name__}")
    return np.asarray(values).reshape(-1)


def constant_pad(value: float) -> float:
    """Half the width given to the range of a field that is ``value`` everywhere (its histogram's and its first
    transfer function's, ``volviz.optics.auto_tf``): a thousandth of the value, at least 1e-6."""
    return max(abs(value) * 1e-3, 1e-6)


def histogram(dataset: Union[Dataset, TimeSeries], bins: int = 128) -> tuple[np.ndarray, np.ndarray]:
    """Counts and bin edges of the finite active-scalar values (NaN/Inf are left out); a constant field's range is
    its value +- ``constant_pad``, as its first transfer function's."""
    values = scalar_values(dataset)
    if values.dtype.kind == "f":
        values = values[np.isfinite(values)]
    if values.size == 0:
        return np.zeros(bins, dtype=np.int64), np.linspace(0.0, 1.0, bins + 1)
    lo, hi = float(values.min()), float(values.max())
    if hi <= lo:
        lo, hi = lo - constant_pad(lo), hi + constant_pad(lo)
    return np.histogram(values, bins=bins, range=(lo, hi))
