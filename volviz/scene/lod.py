"""Compressed volumes (``.vvz``) drawn at a view-dependent level of detail (Guthe §2.3.6): when a file is too large to
decode whole, and what a ``LodTree`` tells without decoding (its range and bounds), for the TF, framing and the
renderer (``volviz.render.lod_volume``)."""
from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from typing_extensions import TypeIs   # (typing's own from Python 3.13)

    from volviz.regular.lod import LodTree

#: compressed volumes with more voxels than this open at a view-dependent level of detail instead of being decoded
LOD_VOXELS = 256 ** 3


def vvz_voxels(path: str | os.PathLike) -> int:
    """Number of voxels of a ``.vvz`` file, from its header (nothing is decoded)."""
    from volviz.regular.nodes import NodeDecoder   # heavy (the wavelet decoder's Numba kernels): only for a .vvz

    return int(np.prod(NodeDecoder(os.fspath(path)).dims))


def is_lod(dataset: object) -> TypeIs[LodTree]:
    """Whether a loaded dataset is a compressed volume drawn at a level of detail. A LodTree exists only once its
    module was imported, so the question never imports that module (the wavelet decoder's Numba kernels and SciPy,
    up to a second of a render of any regular volume, issue #30; docs/bench/docstring-figures.md)."""
    lod = sys.modules.get("volviz.regular.lod")
    return lod is not None and isinstance(dataset, lod.LodTree)


def lod_scalar_range(tree: LodTree) -> tuple[float, float]:
    """The data range of the whole volume (from the finest level's per-node statistics, no decoding)."""
    st = tree.stats[0]
    return float(tree._to_data(st.vmin.min())), float(tree._to_data(st.vmax.max()))


def lod_bounds(tree: LodTree) -> tuple[float, float, float, float, float, float]:
    """(xmin, xmax, ymin, ymax, zmin, zmax) of the volume's samples."""
    hi = tree.origin + (np.asarray(tree.shapes[0], float) - 1.0) * tree.spacing
    return tuple(float(v) for pair in zip(tree.origin, hi) for v in pair)  # type: ignore[return-value]
