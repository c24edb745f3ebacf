"""Small synthetic tetrahedral meshes for tests, demos and sort validation: a convex box, boxes with a cavity or a
through-hole, disconnected pieces, and three "pencil" tetrahedra forming a visibility cycle (Guthe §4.3 / §7.2: the
hard cases for MPVO)."""
from __future__ import annotations

from typing import Callable

import numpy as np

from volviz.model.datasets import VTK_HEXAHEDRON, CurvilinearGrid, TetMesh, UnstructuredMesh
from volviz.unstructured.tetrahedralize import tetrahedralize


def _default_field(p: np.ndarray) -> np.ndarray:
    return np.sqrt(((p - 0.5) ** 2).sum(axis=-1))


def box_grid(n: int = 4, field: Callable[[np.ndarray], np.ndarray] = _default_field, jitter: float = 0.0,
             seed: int = 0) -> CurvilinearGrid:
    """An n x n x n point grid on the unit cube (optionally jittered), scalar ``field(points)``."""
    g = np.linspace(0.0, 1.0, n)
    pts = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1)
    if jitter:
        rng = np.random.default_rng(seed)
        inner = (slice(1, -1),) * 3
        pts[inner] += rng.uniform(-jitter, jitter, pts[inner].shape) / (n - 1)
    return CurvilinearGrid(pts, {"f": field(pts)})


def box_tets(n: int = 4, **kw) -> TetMesh:
    """The tetrahedralised :func:`box_grid` (convex)."""
    return tetrahedralize(box_grid(n, **kw))


def carved_box(n: int, remove: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
               field: Callable[[np.ndarray], np.ndarray] = _default_field) -> TetMesh:
    """An (n-1)^3 hexahedral box without the cells where ``remove(i, j, k)`` is True, as a TetMesh."""
    g = np.linspace(0.0, 1.0, n)
    pts = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3, order="F")
    i, j, k = (a.ravel(order="F") for a in np.meshgrid(*(np.arange(n - 1),) * 3, indexing="ij"))
    keep = ~remove(i, j, k)
    i, j, k = i[keep], j[keep], k[keep]

    def idx(di: int, dj: int, dk: int) -> np.ndarray:
        return (i + di) + n * ((j + dj) + n * (k + dk))

    hexes = np.stack([idx(0, 0, 0), idx(1, 0, 0), idx(1, 1, 0), idx(0, 1, 0),
                      idx(0, 0, 1), idx(1, 0, 1), idx(1, 1, 1), idx(0, 1, 1)], axis=1)
    um = UnstructuredMesh(pts, [(VTK_HEXAHEDRON, hexes)], {"f": field(pts)})
    return tetrahedralize(um)


def cavity_box(n: int = 6) -> TetMesh:
    """A box with an enclosed empty cavity in the middle (non-convex boundary inside)."""
    lo, hi = (n - 1) // 3, n - 1 - (n - 1) // 3
    return carved_box(n, lambda i, j, k: (i >= lo) & (i < hi) & (j >= lo) & (j < hi) & (k >= lo) & (k < hi))


def holed_box(n: int = 6) -> TetMesh:
    """A box with a square through-hole along z (a thick torus)."""
    lo, hi = (n - 1) // 3, n - 1 - (n - 1) // 3
    return carved_box(n, lambda i, j, k: (i >= lo) & (i < hi) & (j >= lo) & (j < hi))


def merge(*meshes: TetMesh, offsets: list[tuple[float, float, float]] | None = None) -> TetMesh:
    """Disjoint union of meshes, each translated by its offset."""
    pts, tets, sc, base = [], [], [], 0
    for i, m in enumerate(meshes):
        off = np.zeros(3) if offsets is None else np.asarray(offsets[i], dtype=np.float64)
        pts.append(m.points + off)
        tets.append(m.tets + base)
        sc.append(m.scalars)
        base += m.n_points
    return TetMesh(np.concatenate(pts), np.concatenate(tets), np.concatenate(sc))


def pencil_cycle(w: float = 0.2, height: float = 1.0) -> TetMesh:
    """Three thin tetrahedra ("pencils") along the sides of a triangle in the xy plane, each rising along its length,
    so that seen from +z pencil 0 covers 1, 1 covers 2 and 2 covers 0: a visibility cycle."""
    ang = np.deg2rad([90.0, 210.0, 330.0])
    v = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    corners: list[np.ndarray] = []
    tets = []
    for i in range(3):
        a, b = v[i], v[(i + 1) % 3]
        d = b - a
        start, end = a - 0.5 * d, b + 0.5 * d            # crossings at 1/4 and 3/4 of the pencil
        perp = np.array([-d[1], d[0]]) / np.linalg.norm(d)
        z0, z1 = -height, height                          # z(u) = (2u - 1) height: -h/2 at u=1/4, +h/2 at u=3/4
        p = [np.r_[start + w * perp, z0], np.r_[start - w * perp, z0], np.r_[end, z1 + w], np.r_[end, z1 - w]]
        corners.extend(p)
        tets.append([4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3])
    pts = np.asarray(corners)
    return tetrahedralize(TetMesh(pts, np.asarray(tets), pts[:, 2] * 0 + 0.5))
