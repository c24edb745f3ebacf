"""The axis order of a volume stored as a plain array (``.npy``, HDF5, Zarr): the reader option ``order``.

``"zyx"`` (the default): a[k, j, i] is the voxel (i, j, k), x fastest in memory: VTK's image layout, XDMF's
description of HDF5 arrays, and how scikit-image, tifffile and napari index volumes. ``"xyz"``: a[i, j, k] is the
voxel (i, j, k), as ``pyvista.wrap`` and Fortran-ordered simulation output index them. A trailing channel axis stays
last either way.
"""
from __future__ import annotations

import numpy as np

from volviz.io.errors import PathLike, ReadError

AXIS_ORDERS = ("zyx", "xyz")


def check_order(path: PathLike, order: str) -> str:
    """``order`` if it is one of ``AXIS_ORDERS``, else a ReadError naming them."""
    if order not in AXIS_ORDERS:
        raise ReadError(path, f"order={order!r} is not one of {', '.join(AXIS_ORDERS)}")
    return order


def to_xyz(data: np.ndarray, order: str) -> np.ndarray:
    """A (z, y, x[, c]) or (x, y, z[, c]) array as (x, y, z[, c]), contiguous."""
    return np.ascontiguousarray(np.moveaxis(data, (0, 1, 2), (2, 1, 0)) if order == "zyx" else data)
