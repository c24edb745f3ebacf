"""Per-mesh precomputation shared by sorting, projection and the reference: face adjacency, boundary faces, face
planes, centroids, circumspheres and per-cell scalar min/max (the zero-opacity test, Roettger §9.1 / §15.1 "ZOT").

Everything geometric is stored relative to ``origin`` (the centre of the mesh's bounding box) so that meshes with
coordinates offset by 1e6 keep full relative precision. Results are kept per mesh while it lives
(``volviz.model.object_cache``) and recomputed when its arrays are replaced; what is derived from a topology later
(float32 planes, inner boundary faces, the sort's work arrays) is kept in its own fields.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Optional

import numpy as np
from numba import njit, prange

from volviz.model.datasets import TetMesh
from volviz.model.extent import point_extent
from volviz.model.object_cache import ObjectCache

#: local vertex ids of face f (the face opposite vertex f), outward for a positively oriented tetrahedron.
FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], dtype=np.int64)


@dataclass
class Topology:
    """Geometry and adjacency of a TetMesh, relative to ``origin``. The adjacency (``neighbor``, ``boundary``) is
    made when first used: a mesh drawn in a given order (the clouds' leaves) never needs it."""

    origin: np.ndarray          # (3,) float64, subtracted from every point
    points: np.ndarray          # (n, 3) float64, relative to origin
    tets: np.ndarray            # (m, 4) int64
    face_n: np.ndarray          # (m, 4, 3) float64 unit outward normals
    face_d: np.ndarray          # (m, 4) float64: n . x = d on the face plane, n . x <= d inside
    centroid: np.ndarray        # (m, 3)
    circ_center: np.ndarray     # (m, 3) circumsphere centres (power-distance sort)
    circ_r2: np.ndarray         # (m,) squared circumradii
    max_edge: float             # longest edge (upper bound of any segment length through one cell)
    # made when first used, by the module whose rule they follow: the boundary faces off the convex hull
    # (``boundary_pairs.inner_boundary``), their cells, vertices, corners and planes (``boundary_pairs``), and a pool of
    # the sort's work arrays (``sort``; private to this package)
    inner_boundary_faces: Optional[np.ndarray] = field(default=None, init=False, repr=False, compare=False)
    inner_face_planes: Optional[tuple[np.ndarray, ...]] = field(default=None, init=False, repr=False, compare=False)
    _sort_work: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=list, init=False, repr=False,
                                                                        compare=False)

    @property
    def n_tets(self) -> int:
        return int(len(self.tets))

    @cached_property
    def neighbor(self) -> np.ndarray:
        """(m, 4) int32 (int64 from 2^31 cells on): the tetrahedron across face f, -1 on the boundary (ValueError
        for a face shared by more than two tetrahedra)."""
        return _face_adjacency(self.tets)

    @cached_property
    def back_face(self) -> np.ndarray:
        """(m,) uint8: for each face f of a cell (bits 2f, 2f + 1), the face of the neighbour there that is shared
        with it, so the sort reads the neighbour's plane of a shared face without searching (0 on the boundary)."""
        return _back_faces(self.neighbor)

    @cached_property
    def planes32(self) -> np.ndarray:
        """(m, 4, 4) float32 face planes (nx, ny, nz, d): the MPVO face sides read 64 bytes per cell from them
        instead of 128 from ``face_n`` / ``face_d`` (one stream, half the memory traffic; ``mpvo``)."""
        planes = np.empty((len(self.face_d), 4, 4), np.float32)
        planes[:, :, :3] = self.face_n
        planes[:, :, 3] = self.face_d
        return planes

    @cached_property
    def boundary(self) -> np.ndarray:
        """(b, 2) int64: (tet, face) of every boundary face."""
        bt, bf = np.nonzero(self.neighbor < 0)
        return np.stack([bt, bf], axis=1).astype(np.int64)


@dataclass
class CellRanges:
    """Per-cell scalar min/max; ``nan`` marks cells with a NaN vertex scalar (rendered transparent)."""

    smin: np.ndarray
    smax: np.ndarray
    nan: np.ndarray


def _face_adjacency(tets: np.ndarray) -> np.ndarray:
    m = len(tets)
    keys = np.sort(tets[:, FACES].reshape(-1, 3), axis=1)        # face id = 4 * tet + f
    order = np.lexsort((keys[:, 2], keys[:, 1], keys[:, 0]))
    sk = keys[order]
    same = np.all(sk[1:] == sk[:-1], axis=1)
    if np.any(same[1:] & same[:-1]):
        raise ValueError("tetrahedral mesh is not manifold: a face is shared by more than two tetrahedra")
    neighbor = np.full(4 * m, -1, dtype=np.int32 if m < 2 ** 31 else np.int64)
    a, b = order[:-1][same], order[1:][same]
    neighbor[a] = b // 4
    neighbor[b] = a // 4
    return neighbor.reshape(m, 4)


@njit(cache=True, nogil=True, parallel=True)
def _back_faces(neighbor: np.ndarray) -> np.ndarray:
    back = np.zeros(len(neighbor), np.uint8)
    for t in prange(len(neighbor)):
        bits = 0
        for f in range(4):
            u = neighbor[t, f]
            if u >= 0:
                for g in range(4):
                    if neighbor[u, g] == t:
                        bits |= g << (2 * f)
        back[t] = bits
    return back


@njit(cache=True, nogil=True, inline="always")
def face_plane(p: np.ndarray, i0: int, i1: int, i2: int) -> tuple[float, float, float, float]:
    """The plane (nx, ny, nz, d) of the face (i0, i1, i2) of the corners ``p`` (4, 3): unit normal (p1 - p0) x
    (p2 - p0) (zero for a degenerate face) and n . x = d on it; outward for ``FACES`` of a positive tetrahedron."""
    ux, uy, uz = p[i1, 0] - p[i0, 0], p[i1, 1] - p[i0, 1], p[i1, 2] - p[i0, 2]
    wx, wy, wz = p[i2, 0] - p[i0, 0], p[i2, 1] - p[i0, 1], p[i2, 2] - p[i0, 2]
    nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    nn = np.sqrt(nx * nx + ny * ny + nz * nz)
    if nn > 0:
        nx, ny, nz = nx / nn, ny / nn, nz / nn
    return nx, ny, nz, nx * p[i0, 0] + ny * p[i0, 1] + nz * p[i0, 2]


@njit(cache=True, nogil=True, parallel=True)
def _geometry(pts: np.ndarray, tets: np.ndarray, faces: np.ndarray, n: np.ndarray, d: np.ndarray,
              centroid: np.ndarray, circ_center: np.ndarray, circ_r2: np.ndarray) -> float:
    """Per tetrahedron (in place): positive orientation (swap vertices 2 and 3 when the signed volume is negative),
    unit outward face normals and plane offsets, centroid, circumsphere (Cramer's rule on 2 (p_i - p_0) . c =
    |p_i - p_0|^2; a degenerate cell gets its centroid and radius 0); returns the longest edge."""
    m = len(tets)
    longest = np.zeros(m)
    for c in prange(m):
        p = np.empty((4, 3))
        for v in range(4):
            for a in range(3):
                p[v, a] = pts[tets[c, v], a]
        e = np.empty((3, 3))
        for i in range(3):
            for a in range(3):
                e[i, a] = p[i + 1, a] - p[0, a]
        vol = (e[0, 0] * (e[1, 1] * e[2, 2] - e[1, 2] * e[2, 1]) - e[0, 1] * (e[1, 0] * e[2, 2] - e[1, 2] * e[2, 0])
               + e[0, 2] * (e[1, 0] * e[2, 1] - e[1, 1] * e[2, 0]))
        if vol < 0:
            tets[c, 2], tets[c, 3] = tets[c, 3], tets[c, 2]
            for a in range(3):
                p[2, a], p[3, a] = p[3, a], p[2, a]
                e[1, a], e[2, a] = e[2, a], e[1, a]
            vol = -vol
        for f in range(4):
            n[c, f, 0], n[c, f, 1], n[c, f, 2], d[c, f] = face_plane(p, faces[f, 0], faces[f, 1], faces[f, 2])
        for a in range(3):
            centroid[c, a] = 0.25 * (p[0, a] + p[1, a] + p[2, a] + p[3, a])
        r0 = 0.5 * (e[0, 0] ** 2 + e[0, 1] ** 2 + e[0, 2] ** 2)
        r1 = 0.5 * (e[1, 0] ** 2 + e[1, 1] ** 2 + e[1, 2] ** 2)
        r2 = 0.5 * (e[2, 0] ** 2 + e[2, 1] ** 2 + e[2, 2] ** 2)
        if vol > 0:
            cx = (r0 * (e[1, 1] * e[2, 2] - e[1, 2] * e[2, 1]) - e[0, 1] * (r1 * e[2, 2] - e[1, 2] * r2)
                  + e[0, 2] * (r1 * e[2, 1] - e[1, 1] * r2)) / vol
            cy = (e[0, 0] * (r1 * e[2, 2] - e[1, 2] * r2) - r0 * (e[1, 0] * e[2, 2] - e[1, 2] * e[2, 0])
                  + e[0, 2] * (e[1, 0] * r2 - r1 * e[2, 0])) / vol
            cz = (e[0, 0] * (e[1, 1] * r2 - r1 * e[2, 1]) - e[0, 1] * (e[1, 0] * r2 - r1 * e[2, 0])
                  + r0 * (e[1, 0] * e[2, 1] - e[1, 1] * e[2, 0])) / vol
            circ_center[c, 0], circ_center[c, 1], circ_center[c, 2] = p[0, 0] + cx, p[0, 1] + cy, p[0, 2] + cz
            circ_r2[c] = cx * cx + cy * cy + cz * cz
        else:
            for a in range(3):
                circ_center[c, a] = centroid[c, a]
            circ_r2[c] = 0.0
        best = 0.0
        for i in range(3):
            for j in range(i + 1, 4):
                best = max(best, (p[j, 0] - p[i, 0]) ** 2 + (p[j, 1] - p[i, 1]) ** 2 + (p[j, 2] - p[i, 2]) ** 2)
        longest[c] = best
    return np.sqrt(longest.max())


def build_topology(mesh: TetMesh) -> Topology:
    """Compute the adjacency and geometry of ``mesh`` (see :func:`topology` for the cached version)."""
    if mesh.n_cells == 0:
        raise ValueError("TetMesh has no tetrahedra")
    in_cells = np.zeros(len(mesh.points), dtype=bool)
    in_cells[mesh.tets.ravel()] = True
    used = mesh.points[in_cells]
    if not np.all(np.isfinite(used)):
        raise ValueError("TetMesh has non-finite point coordinates")
    lo, hi = point_extent(used)
    origin = 0.5 * (lo + hi)
    pts = np.ascontiguousarray(mesh.points - origin)
    tets = np.ascontiguousarray(mesh.tets, dtype=np.int64).copy()
    m = len(tets)
    n = np.empty((m, 4, 3))
    d = np.empty((m, 4))
    centroid = np.empty((m, 3))
    circ_center = np.empty((m, 3))
    circ_r2 = np.empty(m)
    max_edge = _geometry(pts, tets, FACES, n, d, centroid, circ_center, circ_r2)
    return Topology(origin, pts, tets, n, d, centroid, circ_center, circ_r2, float(max_edge))


#: per mesh while it lives: its topology and cell ranges, with the identity of the arrays they were made from
_TOPOLOGIES: ObjectCache[tuple[tuple[object, ...], Topology]] = ObjectCache()
_RANGES: ObjectCache[tuple[tuple[object, ...], CellRanges]] = ObjectCache()


def topology(mesh: TetMesh) -> Topology:
    """The cached :class:`Topology` of ``mesh`` (rebuilt when ``mesh.points`` or ``mesh.tets`` are replaced)."""
    key = (id(mesh.points), id(mesh.tets), mesh.points.shape, mesh.tets.shape)
    cached = _TOPOLOGIES.get(mesh)
    if cached is not None and cached[0] == key:
        return cached[1]
    topo = build_topology(mesh)
    _TOPOLOGIES.put(mesh, (key, topo))
    return topo


def cell_ranges(mesh: TetMesh) -> CellRanges:
    """Cached per-cell scalar min/max over the four vertices, with a NaN flag."""
    key = (id(mesh.scalars), id(mesh.tets), mesh.tets.shape)
    cached = _RANGES.get(mesh)
    if cached is not None and cached[0] == key:
        return cached[1]
    s = mesh.scalars[mesh.tets]
    nan = np.isnan(s).any(axis=1)
    with np.errstate(invalid="ignore"):
        ranges = CellRanges(np.nanmin(np.where(nan[:, None], 0.0, s), axis=1),
                            np.nanmax(np.where(nan[:, None], 0.0, s), axis=1), nan)
    _RANGES.put(mesh, (key, ranges))
    return ranges


def visible_cells(mesh: TetMesh, control_scalars: np.ndarray, control_rho: np.ndarray) -> np.ndarray:
    """Boolean mask of cells whose scalar range meets a part of the TF with rho > 0 (exact for piecewise-linear rho,
    ``visible_ranges``). Cells with a NaN vertex scalar are invisible."""
    r = cell_ranges(mesh)
    return visible_ranges(r.smin, r.smax, control_scalars, control_rho) & ~r.nan


def visible_intervals(control_scalars: np.ndarray, control_rho: np.ndarray) -> list[tuple[float, float]]:
    """The closed scalar intervals where the TF has rho > 0, overlapping and touching ones merged, in order.

    rho is positive on the open piece between control points i, i+1 iff rho_i > 0 or rho_{i+1} > 0; outside
    [first, last] it is zero.
    """
    x = np.asarray(control_scalars, dtype=np.float64)
    rho = np.asarray(control_rho, dtype=np.float64)
    pieces = sorted((float(x[i]), float(x[i + 1])) for i in range(len(x) - 1) if rho[i] > 0 or rho[i + 1] > 0)
    if len(x) == 1 and rho[0] > 0:
        pieces = [(float(x[0]), float(x[0]))]
    merged: list[tuple[float, float]] = []
    for lo, hi in pieces:
        if merged and lo <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], hi))
        else:
            merged.append((lo, hi))
    return merged


def visible_ranges(smin: np.ndarray, smax: np.ndarray, control_scalars: np.ndarray, control_rho: np.ndarray
                   ) -> np.ndarray:
    """Boolean mask of the cells with scalar ranges [smin, smax] that meet a part of the TF with rho > 0
    (``visible_intervals``)."""
    vis = np.zeros(len(smin), dtype=bool)
    for lo, hi in visible_intervals(control_scalars, control_rho):
        vis |= (smax >= lo) & (smin <= hi)
    return vis
