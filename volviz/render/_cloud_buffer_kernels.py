"""Numba kernel of ``volviz.render.gl_nature.cloud_buffers``: the GPU PT pass's vertex buffer for a frame's cloud
tetrahedra (Roettger §11.3-11.6 drawn by ``volviz.render.gl_pt``), written in one pass per tetrahedron instead of
per-cell NumPy arrays repeated at the four vertices."""
from __future__ import annotations

import numpy as np
from numba import njit, prange

N_ATTRIBUTES = 7     # ptPlane0..3, ptScalar, ptRange, ptModulate (gl_pt's cell attributes and the clouds' one)


@njit(cache=True, nogil=True)
def _affine(p: np.ndarray, v0: float, v1: float, v2: float, v3: float, out: np.ndarray) -> None:
    """(gx, gy, gz, c) with g . x + c = v_i at the 4 corners ``p`` (4, 3) (Cramer's rule; g = 0 if flat)."""
    e = np.empty((3, 3))
    for i in range(3):
        for a in range(3):
            e[i, a] = p[i + 1, a] - p[0, a]
    dv = (v1 - v0, v2 - v0, v3 - v0)
    det = (e[0, 0] * (e[1, 1] * e[2, 2] - e[1, 2] * e[2, 1]) - e[0, 1] * (e[1, 0] * e[2, 2] - e[1, 2] * e[2, 0])
           + e[0, 2] * (e[1, 0] * e[2, 1] - e[1, 1] * e[2, 0]))
    g = np.zeros(3)
    if abs(det) > 1e-300:
        for col in range(3):
            m = e.copy()
            for i in range(3):
                m[i, col] = dv[i]
            g[col] = (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1])
                      - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
                      + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0])) / det
    out[0], out[1], out[2] = g[0], g[1], g[2]
    out[3] = v0 - (g[0] * p[0, 0] + g[1] * p[0, 1] + g[2] * p[0, 2])


@njit(cache=True, nogil=True, parallel=True)
def cloud_vertex_buffer(points: np.ndarray, tets: np.ndarray, face_n: np.ndarray, face_d: np.ndarray,
                        scalars: np.ndarray, modulation: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For tetrahedra ``tets`` (m, 4) of ``points`` (n, 3, relative to the mesh's centre), positively oriented with
    unit outward face planes ``face_n`` (m, 4, 3) / ``face_d`` (m, 4) (``volviz.unstructured.topology``), and the
    per-point ``scalars`` (the table field) and ``modulation``: the vertex positions (4m, 3) float32 and the
    attributes (7, 4m, 4) float32, each tetrahedron's at its 4 vertices: the four face planes (n, d), the scalar's
    affine form (g, c), its (min, max, 0, 0) over the cell, and the modulation's affine form; and the scalar's
    (min, max) per cell as float64 (m, 2), for the TF's culling."""
    m = tets.shape[0]
    pos = np.empty((4 * m, 3), dtype=np.float32)
    attr = np.empty((N_ATTRIBUTES, 4 * m, 4), dtype=np.float32)
    ranges = np.empty((m, 2))
    for c in prange(m):
        p = np.empty((4, 3))
        for v in range(4):
            for a in range(3):
                p[v, a] = points[tets[c, v], a]
        cell = np.empty((N_ATTRIBUTES, 4))
        for f in range(4):
            for a in range(3):
                cell[f, a] = face_n[c, f, a]
            cell[f, 3] = face_d[c, f]
        s = (scalars[tets[c, 0]], scalars[tets[c, 1]], scalars[tets[c, 2]], scalars[tets[c, 3]])
        _affine(p, s[0], s[1], s[2], s[3], cell[4])
        cell[5, 0] = min(min(s[0], s[1]), min(s[2], s[3]))
        cell[5, 1] = max(max(s[0], s[1]), max(s[2], s[3]))
        ranges[c, 0], ranges[c, 1] = cell[5, 0], cell[5, 1]
        cell[5, 2] = 0.0
        cell[5, 3] = 0.0
        _affine(p, modulation[tets[c, 0]], modulation[tets[c, 1]], modulation[tets[c, 2]], modulation[tets[c, 3]],
                cell[6])
        for v in range(4):
            for a in range(3):
                pos[4 * c + v, a] = p[v, a]
            for k in range(N_ATTRIBUTES):
                for a in range(4):
                    attr[k, 4 * c + v, a] = cell[k, a]
    return pos, attr, ranges
