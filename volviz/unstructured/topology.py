"""Per-mesh precomputation shared by sorting, projection and the reference: face adjacency, boundary faces, face
planes, centroids, circumspheres and per-cell scalar min/max (the zero-opacity test, Roettger §9.1 / §15.1 "ZOT").

Everything geometric is stored relative to ``origin`` (the centre of the mesh's bounding box) so that meshes with
coordinates offset by 1e6 keep full relative precision. Results are cached on the mesh object and recomputed when its
arrays are replaced.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volviz.model.datasets import TetMesh

#: local vertex ids of face f (the face opposite vertex f), outward for a positively oriented tetrahedron.
FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], dtype=np.int64)


@dataclass
class Topology:
    """Geometry and adjacency of a TetMesh, relative to ``origin``."""

    origin: np.ndarray          # (3,) float64, subtracted from every point
    points: np.ndarray          # (n, 3) float64, relative to origin
    tets: np.ndarray            # (m, 4) int64
    neighbor: np.ndarray        # (m, 4) int64: tetrahedron across face f, -1 on the boundary
    boundary: np.ndarray        # (b, 2) int64: (tet, face) of every boundary face
    face_n: np.ndarray          # (m, 4, 3) float64 unit outward normals
    face_d: np.ndarray          # (m, 4) float64: n . x = d on the face plane, n . x <= d inside
    centroid: np.ndarray        # (m, 3)
    circ_center: np.ndarray     # (m, 3) circumsphere centres (power-distance sort)
    circ_r2: np.ndarray         # (m,) squared circumradii
    max_edge: float             # longest edge (upper bound of any segment length through one cell)

    @property
    def n_tets(self) -> int:
        return int(len(self.tets))


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
    neighbor = np.full(4 * m, -1, dtype=np.int64)
    a, b = order[:-1][same], order[1:][same]
    neighbor[a] = b // 4
    neighbor[b] = a // 4
    return neighbor.reshape(m, 4)


def build_topology(mesh: TetMesh) -> Topology:
    """Compute the adjacency and geometry of ``mesh`` (see :func:`topology` for the cached version)."""
    if mesh.n_cells == 0:
        raise ValueError("TetMesh has no tetrahedra")
    used = mesh.points[np.unique(mesh.tets)]
    if not np.all(np.isfinite(used)):
        raise ValueError("TetMesh has non-finite point coordinates")
    origin = 0.5 * (used.min(axis=0) + used.max(axis=0))
    pts = mesh.points - origin
    tets = mesh.tets
    p = pts[tets]
    vol6 = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
    tets = tets.copy()
    neg = vol6 < 0
    tets[neg, 2], tets[neg, 3] = mesh.tets[neg, 3], mesh.tets[neg, 2]
    p = pts[tets]
    neighbor = _face_adjacency(tets)
    fv = p[:, FACES]                                              # (m, 4, 3, 3)
    n = np.cross(fv[:, :, 1] - fv[:, :, 0], fv[:, :, 2] - fv[:, :, 0])
    norm = np.linalg.norm(n, axis=2, keepdims=True)
    n = n / np.where(norm > 0, norm, 1.0)
    d = np.einsum("ijk,ijk->ij", n, fv[:, :, 0])
    bt, bf = np.nonzero(neighbor < 0)
    centroid = p.mean(axis=1)
    # circumsphere: solve 2 (p_i - p_0) . c = |p_i|^2 - |p_0|^2 in coordinates relative to p_0
    e = p[:, 1:] - p[:, :1]
    rhs = 0.5 * (e ** 2).sum(axis=2)
    det = np.linalg.det(e)
    ok = np.abs(det) > 0
    c = np.zeros((len(tets), 3))
    c[ok] = np.linalg.solve(e[ok], rhs[ok][..., None])[..., 0]
    circ_center = p[:, 0] + c
    circ_r2 = (c ** 2).sum(axis=1)
    circ_center[~ok], circ_r2[~ok] = centroid[~ok], 0.0
    edges = p[:, [1, 2, 3, 2, 3, 3]] - p[:, [0, 0, 0, 1, 1, 2]]
    max_edge = float(np.sqrt((edges ** 2).sum(axis=2).max()))
    return Topology(origin, np.ascontiguousarray(pts), np.ascontiguousarray(tets), neighbor,
                    np.stack([bt, bf], axis=1).astype(np.int64), np.ascontiguousarray(n), np.ascontiguousarray(d),
                    centroid, circ_center, circ_r2, max_edge)


def topology(mesh: TetMesh) -> Topology:
    """The cached :class:`Topology` of ``mesh`` (rebuilt when ``mesh.points`` or ``mesh.tets`` are replaced)."""
    key = (id(mesh.points), id(mesh.tets), mesh.points.shape, mesh.tets.shape)
    cached = mesh.__dict__.get("_volviz_topology")
    if cached is not None and cached[0] == key:
        return cached[1]
    topo = build_topology(mesh)
    mesh.__dict__["_volviz_topology"] = (key, topo)
    return topo


def cell_ranges(mesh: TetMesh) -> CellRanges:
    """Cached per-cell scalar min/max over the four vertices, with a NaN flag."""
    key = (id(mesh.scalars), id(mesh.tets), mesh.tets.shape)
    cached = mesh.__dict__.get("_volviz_ranges")
    if cached is not None and cached[0] == key:
        return cached[1]
    s = mesh.scalars[mesh.tets]
    nan = np.isnan(s).any(axis=1)
    with np.errstate(invalid="ignore"):
        ranges = CellRanges(np.nanmin(np.where(nan[:, None], 0.0, s), axis=1),
                            np.nanmax(np.where(nan[:, None], 0.0, s), axis=1), nan)
    mesh.__dict__["_volviz_ranges"] = (key, ranges)
    return ranges


def visible_cells(mesh: TetMesh, control_scalars: np.ndarray, control_rho: np.ndarray) -> np.ndarray:
    """Boolean mask of cells whose scalar range meets a part of the TF with rho > 0 (exact for piecewise-linear rho).

    rho is positive on the open piece between control points i, i+1 iff rho_i > 0 or rho_{i+1} > 0; outside
    [first, last] it is zero. Cells with a NaN vertex scalar are invisible.
    """
    r = cell_ranges(mesh)
    x = np.asarray(control_scalars, dtype=np.float64)
    rho = np.asarray(control_rho, dtype=np.float64)
    vis = np.zeros(len(r.smin), dtype=bool)
    for i in range(len(x) - 1):
        if rho[i] > 0 or rho[i + 1] > 0:
            vis |= (r.smax >= x[i]) & (r.smin <= x[i + 1])
    if len(x) == 1 and rho[0] > 0:
        vis |= (r.smin <= x[0]) & (r.smax >= x[0])
    return vis & ~r.nan
