"""Numba kernel of ``volviz.render.gl_nature.cloud_buffers``: the GPU PT pass's vertex positions and per-tetrahedron
cell data for a frame's cloud leaves (Roettger §11.3-11.6 drawn by ``volviz.render.gl_pt``), written in one parallel
pass over the leaves: each leaf's 5 tetrahedra (``CloudFrame.to_tetmesh``'s split and back-to-front order within the
leaf) with their corners, face planes and the affine forms of the table field and the modulating field, without
building a tetrahedral mesh."""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from volviz.unstructured.topology import FACES, face_plane

N_ATTRIBUTES = 7     # ptPlane0..3, ptScalar, ptRange, ptModulate (gl_pt's cell attributes and the clouds' one)

#: the 5 tetrahedra of a leaf cube by corner (q = 4 i + 2 j + k), for even and odd leaves (``CloudFrame.to_tetmesh``)
EVEN = np.array([[0, 6, 5, 3], [4, 0, 6, 5], [2, 0, 6, 3], [1, 0, 5, 3], [7, 6, 5, 3]], dtype=np.int64)
ODD = np.array([[4, 2, 1, 7], [0, 4, 2, 1], [6, 4, 2, 7], [5, 4, 1, 7], [3, 2, 1, 7]], dtype=np.int64)


@njit(cache=True, nogil=True, inline="always")
def _det3(e: np.ndarray) -> float:
    return (e[0, 0] * (e[1, 1] * e[2, 2] - e[1, 2] * e[2, 1]) - e[0, 1] * (e[1, 0] * e[2, 2] - e[1, 2] * e[2, 0])
            + e[0, 2] * (e[1, 0] * e[2, 1] - e[1, 1] * e[2, 0]))


@njit(cache=True, nogil=True, inline="always")
def _affine(p: np.ndarray, v: np.ndarray, out: np.ndarray, e: np.ndarray, m: np.ndarray, g: np.ndarray) -> None:
    """(gx, gy, gz, c) with g . x + c = v[i] at the 4 corners ``p`` (4, 3) (Cramer's rule; g = 0 if flat); ``e``,
    ``m`` (3, 3) and ``g`` (3,) are scratch."""
    for i in range(3):
        for a in range(3):
            e[i, a] = p[i + 1, a] - p[0, a]
    det = _det3(e)
    g[:] = 0.0
    if abs(det) > 1e-300:
        for col in range(3):
            for i in range(3):
                for a in range(3):
                    m[i, a] = v[i + 1] - v[0] if a == col else e[i, a]
            g[col] = _det3(m) / det
    out[0], out[1], out[2] = g[0], g[1], g[2]
    out[3] = v[0] - (g[0] * p[0, 0] + g[1] * p[0, 1] + g[2] * p[0, 2])


@njit(cache=True, nogil=True, parallel=True)
def leaf_vertex_buffer(leaves: np.ndarray, root: int, shape: np.ndarray, origin: np.ndarray, spacing: np.ndarray,
                       centre: np.ndarray, table: np.ndarray, other: np.ndarray, m_scale: float, eye: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For the frame's ``leaves`` (L, 4: level, a, b, c; back to front) of a cloud volume (``shape`` points, octree
    ``root`` size, grid ``origin`` and ``spacing``) with the morphed ``table`` and ``other`` fields (flat, C order):
    per tetrahedron, 5 per leaf in back-to-front order for ``eye`` (the corner tetrahedra behind the central one, the
    central one, those in front), the vertex positions relative to ``centre`` (20L, 3) float32 (tetrahedron t's at
    4 t ... 4 t + 3); the cell data (5L, 7, 4) float32 per tetrahedron: the four unit outward face planes (n, d)
    (vertices 2 and 3 swapped where the tetrahedron is negatively oriented), the table field's affine form (g, c),
    its (min, max, 0, 0), and the affine form of ``other`` / ``m_scale`` (the length modulation, Eq. 11.9); and the
    table field's (min, max) per tetrahedron as float64 (5L, 2), for the TF's culling."""
    n_leaves = leaves.shape[0]
    m = 5 * n_leaves
    pos = np.empty((4 * m, 3), dtype=np.float32)
    cells = np.empty((m, N_ATTRIBUTES, 4), dtype=np.float32)
    ranges = np.empty((m, 2))
    ny, nz = shape[1], shape[2]
    chunks = min(n_leaves, 64)
    for chunk in prange(chunks):
        u = np.empty(3)                      # scratch, one set per chunk of leaves
        front = np.zeros(5, dtype=np.bool_)
        order = np.empty(5, dtype=np.int64)
        p = np.empty((4, 3))
        sv = np.empty(4)
        mv = np.empty(4)
        cell = np.empty((N_ATTRIBUTES, 4))
        e = np.empty((3, 3))
        em = np.empty((3, 3))
        g = np.empty(3)
        for leaf in range(chunk * n_leaves // chunks, (chunk + 1) * n_leaves // chunks):
            _leaf(leaves, leaf, root, ny, nz, origin, spacing, centre, table, other, m_scale, eye, u, front, order,
                  p, sv, mv, cell, e, em, g, pos, cells, ranges)
    return pos, cells, ranges


@njit(cache=True, nogil=True, inline="always")
def _leaf(leaves: np.ndarray, leaf: int, root: int, ny: int, nz: int, origin: np.ndarray, spacing: np.ndarray,
          centre: np.ndarray, table: np.ndarray, other: np.ndarray, m_scale: float, eye: np.ndarray, u: np.ndarray,
          front: np.ndarray, order: np.ndarray, p: np.ndarray, sv: np.ndarray, mv: np.ndarray, cell: np.ndarray,
          e: np.ndarray, em: np.ndarray, g: np.ndarray, pos: np.ndarray, cells: np.ndarray, ranges: np.ndarray
          ) -> None:
    """One leaf of ``leaf_vertex_buffer``: its 5 tetrahedra at 5 * leaf ... (the arrays after ``eye`` are scratch)."""
    s = root >> leaves[leaf, 0]
    a, b, c = leaves[leaf, 1], leaves[leaf, 2], leaves[leaf, 3]
    local = ODD if (a + b + c) % 2 == 1 else EVEN
    # the tetrahedra's order within the leaf: corner tetrahedra behind the central one, it, those in front
    for ax, idx in enumerate((a, b, c)):
        u[ax] = (eye[ax] - (origin[ax] + idx * s * spacing[ax])) / (s * spacing[ax])
    front[:] = False
    for t in range(1, 5):
        q = local[t, 0]
        total = 0.0
        for ax in range(3):
            bit = (q >> (2 - ax)) & 1
            total += u[ax] if bit == 0 else 1.0 - u[ax]
        front[t] = total < 1.0
    k = 0
    for t in range(1, 5):
        if not front[t]:
            order[k] = t
            k += 1
    order[k] = 0
    k += 1
    for t in range(1, 5):
        if front[t]:
            order[k] = t
            k += 1
    for slot in range(5):
        t = order[slot]
        tet = 5 * leaf + slot
        for v in range(4):
            q = local[t, v]
            gi, gj, gk = (a + (q >> 2)) * s, (b + ((q >> 1) & 1)) * s, (c + (q & 1)) * s
            p[v, 0] = origin[0] + gi * spacing[0] - centre[0]
            p[v, 1] = origin[1] + gj * spacing[1] - centre[1]
            p[v, 2] = origin[2] + gk * spacing[2] - centre[2]
            flat = (gi * ny + gj) * nz + gk
            sv[v] = table[flat]
            mv[v] = other[flat] / m_scale
        for i in range(3):
            for ax in range(3):
                e[i, ax] = p[i + 1, ax] - p[0, ax]
        if _det3(e) < 0.0:
            for ax in range(3):
                p[2, ax], p[3, ax] = p[3, ax], p[2, ax]
            sv[2], sv[3] = sv[3], sv[2]
            mv[2], mv[3] = mv[3], mv[2]
        for f in range(4):
            cell[f, 0], cell[f, 1], cell[f, 2], cell[f, 3] = face_plane(p, FACES[f, 0], FACES[f, 1], FACES[f, 2])
        _affine(p, sv, cell[4], e, em, g)
        cell[5, 0] = min(min(sv[0], sv[1]), min(sv[2], sv[3]))
        cell[5, 1] = max(max(sv[0], sv[1]), max(sv[2], sv[3]))
        cell[5, 2] = 0.0
        cell[5, 3] = 0.0
        ranges[tet, 0], ranges[tet, 1] = cell[5, 0], cell[5, 1]
        _affine(p, mv, cell[6], e, em, g)
        for v in range(4):
            for ax in range(3):
                pos[4 * tet + v, ax] = p[v, ax]
        for kk in range(N_ATTRIBUTES):
            for ax in range(4):
                cells[tet, kk, ax] = cell[kk, ax]
