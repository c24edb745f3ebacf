"""Terrain C-LOD: Roettger's quadtree triangulation with geomorphing (Roettger §3.5.3, [89]; digest §2.4).

- **Representation**: a (2^n + 1)^2 height field (``HeightField``; other sizes are resampled) and per-node values in
  quadtree matrices at the node centres.
- **Roughness d2** (precomputed, [89]): d2 = max_i |dh_i| / d over the six elevation differences at the 4 edge
  midpoints and the 2 diagonal midpoints of a node of edge length d (world units). Extra layers (a fog map, §10.4) add
  their own d2 scaled by a weight; the node keeps the **maximum of the weighted curvatures**.
- **Propagation** bottom-up with K = C / (2 (C - 1)) (valid for C > 2): d2(node) := max(d2_local, K d2(child)), so a
  node refines whenever one of its children would (digest §2.4).
- **Criterion** Eq. (3.2): f = l / (d C max(c d2, 1)); refine if f < 1. l is the L1 distance from the eye to the node
  centre (at its true elevation), as in [89]; d the node edge length (the larger of the two spacings).
- **Triangle fans** around each leaf's centre, with the edge midpoints skipped where the neighbour of the same size
  does not exist (T-vertex rule); a conformity guard refines a node only if the nodes of its parent's size across its
  outer edges are refined, so no T-junction can occur (the guard's binding count is reported; with the K propagation it
  is normally zero).
- **Geomorphing**: a refined node gets the factor w = clamp(1/f - 1, 0, 1) (the §11.4 mapping e' = clamp(e - 1, 0, 1)
  with e = 1/f, the documented analogue, since the thesis gives no terrain formula), capped by the factors of its parent
  and its guard neighbours. Each vertex the refinement introduces is the midpoint of an edge of the coarser fan and is
  drawn at (1 - w) * (average of the edge's morphed endpoints) + w * (true value); shared edge points use the minimum
  factor of both nodes. At w = 0 the refined mesh is geometrically identical to the unrefined one, so refinement never
  pops: vertex positions are continuous functions of the eye position (tested).
- Every extra layer (fog top, cloud-layer base/top as absolute heights) is morphed with the same weights, so prisms
  stacked on the triangles stay attached to the terrain.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numba
import numpy as np

from volviz.nature import _terrain_kernels as K
from volviz.nature.heightfield import HeightField
from volviz.numba_threads import numba_threads


def propagation_factor(big_c: float) -> float:
    """K = C / (2 (C - 1)) of the d2 propagation (digest §2.4, [89]); needs C > 2."""
    if not big_c > 2.0:
        raise ValueError(f"the minimum resolution C must be > 2 for the d2 propagation, got {big_c}")
    return big_c / (2.0 * (big_c - 1.0))


@dataclass
class TerrainMesh:
    """One frame's triangulation: points (n, 3) with morphed heights, triangles (m, 3) counter-clockwise from above."""

    points: np.ndarray
    triangles: np.ndarray
    grid_index: np.ndarray          # (n, 2) grid indices (i, j) of every vertex
    layers: dict[str, np.ndarray]   # morphed extra layers per vertex (absolute heights), by name
    tcoords: np.ndarray             # (n, 2) texture coordinates u = i / (N - 1), v = j / (N - 1) (v = 1 is north)
    stats: dict[str, float] = field(default_factory=dict)

    @property
    def n_triangles(self) -> int:
        return int(len(self.triangles))

    def to_pyvista(self, normals: np.ndarray | None = None):
        # PyVista (VTK, heavy): only where the terrain is drawn by VTK
        import pyvista as pv

        mesh = pv.PolyData.from_regular_faces(self.points, self.triangles)
        mesh.active_texture_coordinates = self.tcoords.astype(np.float32)
        if normals is not None:
            mesh.point_data["Normals"] = normals
            mesh.point_data.active_normals_name = "Normals"
        return mesh


def frustum_planes(camera, size: tuple[int, int], margin: float = 0.0) -> np.ndarray:
    """(5, 4) planes a x + b y + c z + d >= 0 inside (left, right, bottom, top, near) of a perspective camera."""
    r, u, f = camera.frame()
    w, h = size
    ty = np.tan(np.radians(camera.view_angle) / 2.0) * (1.0 + margin)
    tx = ty * w / h
    eye = np.asarray(camera.position, dtype=np.float64)
    normals = [f * tx + r, f * tx - r, f * ty + u, f * ty - u]
    planes = []
    for nrm in normals:
        nrm = nrm / np.linalg.norm(nrm)
        planes.append([*nrm, -float(nrm @ eye)])
    near = camera.clipping_range[0]
    planes.append([*f, -float(f @ eye) - near])
    return np.asarray(planes, dtype=np.float64)


class TerrainLOD:
    """Roettger's C-LOD over a ``HeightField`` plus optional morphed layers (see the module docstring).

    ``layers``: name -> (N, N) absolute heights morphed with the terrain (e.g. fog top = terrain + thickness).
    ``curvature``: extra (grid (N, N), weight) pairs whose weighted d2 enters the maximum (e.g. the fog map, §10.4).
    """

    def __init__(self, terrain: HeightField, layers: dict[str, np.ndarray] | None = None,
                 curvature: Sequence[tuple[np.ndarray, float]] = (), big_c: float = 9.0, small_c: float = 2.0,
                 geomorph: bool = True) -> None:
        self.terrain = terrain
        n = terrain.size
        self.n = n
        self.layer_names = list(layers or {})
        stack = [terrain.heights] + [np.asarray(layers[k], dtype=np.float64) for k in self.layer_names]  # type: ignore
        for name, arr in zip(["terrain"] + self.layer_names, stack):
            if arr.shape != (n, n) or not np.all(np.isfinite(arr)):
                raise ValueError(f"layer {name!r} must be a finite ({n}, {n}) array, got {arr.shape}")
        self.fields = np.ascontiguousarray(np.stack(stack, axis=-1))     # (n, n, F): a point's values side by side
        self._z_range = np.array([self.fields.min(), self.fields.max()])  # bounds every morphed value
        self.big_c = float(big_c)
        self.small_c = float(small_c)
        self.geomorph = bool(geomorph)
        self.k = propagation_factor(self.big_c)
        unit = max(terrain.spacing)
        d2 = np.zeros((n, n))
        K.local_d2(terrain.heights, n, unit, d2, 1.0)
        for grid, weight in curvature:
            g = np.asarray(grid, dtype=np.float64)
            if g.shape != (n, n):
                raise ValueError(f"curvature grid must be ({n}, {n}), got {g.shape}")
            K.local_d2(g, n, unit, d2, float(weight))
        self.d2_local = d2.copy()
        K.propagate_d2(d2, n, self.k)
        self.d2 = d2
        self._state = np.zeros((n, n), dtype=np.int8)
        self._weight = np.zeros((n, n))
        cap = ((n - 1) ** 2) // 2 + 8
        self._nodes = np.zeros((cap, 2), dtype=np.int64)
        self._sizes = np.zeros(cap, dtype=np.int64)
        self._morphed = np.zeros_like(self.fields)
        self._vmap = np.zeros((n, n, 2), dtype=np.int32)       # per grid point: (stamp of its frame, vertex id)
        self._stamp = 0

    def set_resolution(self, small_c: float) -> None:
        """The global resolution c (the triangle-count knob of Eq. 3.2)."""
        self.small_c = float(small_c)

    def update(self, eye: Sequence[float], planes: np.ndarray | None = None,
               emit_threads: Callable[[], int] | None = None, detail: float = 1.0) -> TerrainMesh:
        """Triangulate for an eye position; ``planes`` (p, 4) culls the leaves outside the frustum (refinement is
        unchanged; only the culled leaves' own vertices are not morphed). ``emit_threads``: asked for the Numba
        thread count of the fan emission when it starts (e.g. more once other work of the frame is done).
        ``detail`` < 1 scales the minimum global resolution C (Eq. 3.2) down for a coarser mesh: about detail²
        of the triangles, for frames drawn while the camera moves."""
        t0 = time.perf_counter()
        n = self.n
        self._state.fill(0)
        self._weight.fill(0.0)
        eye_a = np.asarray(eye, dtype=np.float64).reshape(3)
        hf = self.terrain
        count, blocked = K.refine(self.d2, hf.heights, n, hf.spacing[0], hf.spacing[1], hf.origin[0], hf.origin[1],
                                  eye_a, self.big_c * float(detail), self.small_c, self.geomorph, self._state,
                                  self._weight, self._nodes, self._sizes)
        pl = np.zeros((0, 4)) if planes is None else np.ascontiguousarray(planes, dtype=np.float64)
        K.morph(self.fields, n, self._state, self._weight, self._nodes, self._sizes, count, self._morphed,
                hf.spacing[0], hf.spacing[1], hf.origin[0], hf.origin[1], pl, self._z_range)
        self._stamp += 1
        n_leaves = int(np.count_nonzero(self._state == 1))
        verts = np.empty((n_leaves * 9 + 8, 2), dtype=np.int64)
        vals = np.empty((n_leaves * 9 + 8, self.fields.shape[2]))
        tris = np.empty((n_leaves * 8 + 8, 3), dtype=np.int32)     # 32-bit: VTK indexes them fastest
        with numba_threads(emit_threads() if emit_threads is not None else numba.get_num_threads()):
            nv, nt = K.emit_fans(n, hf.spacing[0], hf.spacing[1], hf.origin[0], hf.origin[1], self._state,
                                 self._nodes, self._sizes, count, self._morphed, pl, self._vmap, self._stamp,
                                 verts, vals, tris)
            verts = verts[:nv]
            vals = vals[:nv]
            pts, tc = K.mesh_arrays(verts, vals, hf.origin[0], hf.origin[1], hf.spacing[0], hf.spacing[1], n)
        layers = {name: vals[:, i + 1].copy() for i, name in enumerate(self.layer_names)}
        stats = {"nodes": float(count), "leaves": float(n_leaves), "triangles": float(nt), "vertices": float(nv),
                 "guard_blocked": float(blocked), "seconds": time.perf_counter() - t0}
        return TerrainMesh(pts, tris[:nt], verts, layers, tc, stats)

    def full_mesh(self) -> TerrainMesh:
        """The full-resolution grid (the reference): every node refined, no morphing (w = 1)."""
        saved = (self.big_c, self.small_c, self.geomorph)
        try:
            self.geomorph = False
            self.big_c = 1e30
            hf = self.terrain
            centre = [hf.origin[0] + 0.5 * hf.extent[0], hf.origin[1] + 0.5 * hf.extent[1], float(hf.heights.mean())]
            return self.update(centre)
        finally:
            self.big_c, self.small_c, self.geomorph = saved

    def vertex_normals(self, mesh: TerrainMesh, normals: np.ndarray | None = None) -> np.ndarray:
        """Full-resolution height-field normals at the mesh vertices (lighting independent of the LOD)."""
        nrm = self.terrain.normals() if normals is None else normals
        return nrm[mesh.grid_index[:, 0], mesh.grid_index[:, 1]]
