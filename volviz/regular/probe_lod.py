"""The probe on a compressed multiresolution volume (``.vvz``, ``LodTree``): the first visible voxel along the ray
through a pixel, at full resolution, whatever level of detail is on screen (Guthe §2.3: the finest level of the
wavelet octree is the volume itself). Only the level-0 nodes the ray crosses are decoded, front to back, through
the tree's node cache, until a visible sample is found; the criterion and the answer are those of
``volviz.model.probe.probe_regular``."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from volviz.model.probe import ProbeResult, first_visible, ray_voxels, voxel_result

from .wavelet import HALF


def lod_voxel_values(tree: Any, ijk: np.ndarray) -> np.ndarray:
    """The full-resolution values (data units, float64) of voxels ``ijk`` (n, 3) of ``tree``, decoding the level-0
    nodes (``HALF``^3 voxels each) that hold them."""
    ijk = np.asarray(ijk, dtype=np.int64).reshape(-1, 3)
    out = np.empty(len(ijk), dtype=np.float64)
    nodes = ijk // HALF
    for key in np.unique(nodes, axis=0):
        rows = np.flatnonzero((nodes == key).all(axis=1))
        data = tree.node((0, tuple(int(v) for v in key)))
        local = ijk[rows] - key * HALF
        out[rows] = tree._to_data(data[local[:, 0], local[:, 1], local[:, 2]])
    return out


def probe_lod(tree: Any, origin: Any, direction: Any, tf: Any = None, component: str = "",
              opacity: float = 1.0, clip: Any = None) -> Optional[ProbeResult]:
    """The first full-resolution voxel of the ``LodTree`` along the ray whose opacity under ``tf`` over half a voxel
    is visible (``probe_regular``'s rule, in the part ``clip`` keeps), with its decoded value, centre and index;
    None when nothing visible is hit. The nodes are decoded one at a time in the ray's order, and the search stops
    at the first hit."""
    d = np.asarray(direction, dtype=np.float64)
    march = ray_voxels(origin, d / np.linalg.norm(d), tree.origin, tree.spacing, tree.decoder.dims, clip)
    if march is None:
        return None
    ijk, step = march
    nodes = ijk // HALF
    change = np.flatnonzero(np.any(np.diff(nodes, axis=0) != 0, axis=1)) + 1
    for run in np.split(np.arange(len(ijk)), change):    # the runs of samples in one node, front to back
        values = lod_voxel_values(tree, ijk[run])
        hit = first_visible(values, tf, opacity, step)
        if hit is not None:
            return voxel_result(component, float(values[hit]), ijk[run[hit]], tree.origin, tree.spacing)
    return None
