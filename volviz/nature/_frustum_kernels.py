"""Numba helper of the terrain and cloud C-LOD kernels: the view-frustum test of an axis-aligned box."""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def box_outside(planes: np.ndarray, x0: float, y0: float, z0: float, x1: float, y1: float, z1: float) -> bool:
    """Whether the box [x0, x1] x [y0, y1] x [z0, z1] lies wholly on the negative side of one of the ``planes``
    (p, 4) (a x + b y + c z + d >= 0 inside): the box corner furthest along each plane's normal is tested."""
    for p in range(planes.shape[0]):
        x = x1 if planes[p, 0] >= 0 else x0
        y = y1 if planes[p, 1] >= 0 else y0
        z = z1 if planes[p, 2] >= 0 else z0
        if planes[p, 0] * x + planes[p, 1] * y + planes[p, 2] * z + planes[p, 3] < 0.0:
            return True
    return False
