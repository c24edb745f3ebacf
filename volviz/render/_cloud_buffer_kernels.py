"""Numba kernel of ``volviz.render.gl_nature.cloud_buffers``: the GPU PT pass's per-leaf buffer for a frame's cloud
leaves (Roettger §11.3-11.6 drawn by ``volviz.render.gl_pt``'s fragment shader), written in one parallel pass over
the leaves: each leaf's place in the grid and its corners' morphed values. The geometry shader
(``resources/shaders/cloud_leaf_gs.glsl``) makes the leaf's 5 tetrahedra from them (``CloudFrame.to_tetmesh``'s
split, ordered back to front within the leaf for the eye), with their face planes and the affine forms of the table
field and the modulating field."""
from __future__ import annotations

import numpy as np
from numba import njit, prange

#: RGBA float texels per leaf: (i, j, k, s) its lowest grid point and edge in grid points, the table field at its 8
#: corners (q = 4 i + 2 j + k; 2 texels), the modulating field over its scale at the 8 corners (2 texels)
N_TEXELS = 5


@njit(cache=True, nogil=True, parallel=True)
def leaf_buffer(leaves: np.ndarray, root: int, shape: np.ndarray, origin: np.ndarray, spacing: np.ndarray,
                centre: np.ndarray, table: np.ndarray, other: np.ndarray, m_scale: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For the frame's ``leaves`` (L, 4: level, a, b, c; back to front) of a cloud volume (``shape`` points, octree
    ``root`` size, grid ``origin`` and ``spacing``) with the morphed ``table`` and ``other`` fields (flat, C order):
    the leaves' lowest corners relative to ``centre`` (L + 2, 3) float32 (the last two rows are left for the
    caller: the volume's box, for VTK's bounds), the per-leaf texels (L, 5, 4) float32 (``N_TEXELS``) and the table
    field's (min, max) over each leaf's corners as float64 (L, 2), for the TF's culling."""
    n_leaves = leaves.shape[0]
    pos = np.empty((n_leaves + 2, 3), dtype=np.float32)
    texels = np.empty((n_leaves, N_TEXELS, 4), dtype=np.float32)
    ranges = np.empty((n_leaves, 2))
    ny, nz = shape[1], shape[2]
    for leaf in prange(n_leaves):
        s = root >> leaves[leaf, 0]
        i0, j0, k0 = leaves[leaf, 1] * s, leaves[leaf, 2] * s, leaves[leaf, 3] * s
        pos[leaf, 0] = origin[0] + i0 * spacing[0] - centre[0]
        pos[leaf, 1] = origin[1] + j0 * spacing[1] - centre[1]
        pos[leaf, 2] = origin[2] + k0 * spacing[2] - centre[2]
        texels[leaf, 0, 0], texels[leaf, 0, 1], texels[leaf, 0, 2], texels[leaf, 0, 3] = i0, j0, k0, s
        lo = np.inf
        hi = -np.inf
        for q in range(8):
            flat = ((i0 + (q >> 2) * s) * ny + j0 + ((q >> 1) & 1) * s) * nz + k0 + (q & 1) * s
            v = table[flat]
            texels[leaf, 1 + (q >> 2), q & 3] = v
            texels[leaf, 3 + (q >> 2), q & 3] = other[flat] / m_scale
            lo = min(lo, v)
            hi = max(hi, v)
        ranges[leaf, 0] = lo
        ranges[leaf, 1] = hi
    return pos, texels, ranges
