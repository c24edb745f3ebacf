"""The probe on a tetrahedral mesh (what the projected-tetrahedra renderers draw, Roettger Ch. 8-9): along the ray
through a pixel, the point where the volume in front of it first reaches ``VISIBLE_OPACITY`` (1 - exp(-∫ρ(s(t)) dt),
ρ the transfer function's extinction times the component's opacity), with the value there interpolated linearly in
its tetrahedron (barycentric, as the renderers interpolate: Roettger §8.1), the tetrahedron's index and its vertex
nearest the point.

The tetrahedra the ray crosses and their entry and exit parameters come from one pass over the mesh (``_ray_spans``,
Numba: each tetrahedron is the intersection of its four faces' half-spaces); front to back, the scalar along the
ray is linear in each tetrahedron, and its optical depth is integrated with ``SUBSTEPS`` midpoint samples."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np
from numba import njit

from volviz.model.probe import VISIBLE_OPACITY, ProbeResult, clip_span

SUBSTEPS = 8     # midpoint samples of the extinction per tetrahedron crossed


@njit(cache=True)
def _ray_spans(points: np.ndarray, tets: np.ndarray, o: np.ndarray,
               d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover (compiled)
    """The tetrahedra the ray ``o + t d`` (t >= 0) crosses, with the parameters where it enters and leaves each."""
    m = tets.shape[0]
    ids = np.empty(m, np.int64)
    t_in = np.empty(m, np.float64)
    t_out = np.empty(m, np.float64)
    n_hit = 0
    for c in range(m):
        lo, hi = 0.0, np.inf
        for f in range(4):                      # the face opposite vertex f
            a = points[tets[c, (f + 1) % 4]]
            b = points[tets[c, (f + 2) % 4]]
            e = points[tets[c, (f + 3) % 4]]
            v = points[tets[c, f]]
            nx = (b[1] - a[1]) * (e[2] - a[2]) - (b[2] - a[2]) * (e[1] - a[1])
            ny = (b[2] - a[2]) * (e[0] - a[0]) - (b[0] - a[0]) * (e[2] - a[2])
            nz = (b[0] - a[0]) * (e[1] - a[1]) - (b[1] - a[1]) * (e[0] - a[0])
            if nx * (v[0] - a[0]) + ny * (v[1] - a[1]) + nz * (v[2] - a[2]) < 0.0:
                nx, ny, nz = -nx, -ny, -nz       # the normal points inside, towards vertex f
            num = nx * (o[0] - a[0]) + ny * (o[1] - a[1]) + nz * (o[2] - a[2])
            den = nx * d[0] + ny * d[1] + nz * d[2]
            if den > 0.0:
                lo = max(lo, -num / den)
            elif den < 0.0:
                hi = min(hi, -num / den)
            elif num < 0.0:
                hi = -1.0                        # parallel to the face and outside it
            if hi <= lo:
                break
        if hi > lo:
            ids[n_hit] = c
            t_in[n_hit] = lo
            t_out[n_hit] = hi
            n_hit += 1
    return ids[:n_hit], t_in[:n_hit], t_out[:n_hit]


def load_kernels() -> None:
    """Any thread: call the probe's kernel on one tetrahedron, with the types ``probe_tetmesh`` calls it with. A
    Numba kernel's first call in a process loads its compiled code from the cache while holding the GIL (issue #28:
    the first probe under the cursor held the GUI thread); a scene's loading calls this for its meshes
    (``volviz.scene.tetra.pt_mesh``)."""
    _ray_spans(np.eye(4, 3), np.arange(4, dtype=np.int64).reshape(1, 4), np.zeros(3), np.array([0.0, 0.0, 1.0]))


def barycentric(points: np.ndarray, tet: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The barycentric coordinates (4,) of point ``x`` in the tetrahedron of vertices ``points[tet]``."""
    p = points[tet]
    lam = np.linalg.solve((p[1:] - p[0]).T, np.asarray(x, dtype=np.float64) - p[0])
    return np.concatenate([[1.0 - lam.sum()], lam])


def tet_value(mesh: Any, cell: int, x: Any) -> float:
    """The scalar of ``mesh`` (a ``TetMesh``) at point ``x`` of tetrahedron ``cell``, interpolated linearly."""
    tet = mesh.tets[cell]
    return float(barycentric(mesh.points, tet, x) @ mesh.scalars[tet])


def probe_tetmesh(mesh: Any, origin: Any, direction: Any, tf: Any = None, component: str = "",
                  opacity: float = 1.0, clip: Any = None) -> Optional[ProbeResult]:
    """The first point of the ``TetMesh`` along the ray (``origin``, unit ``direction``) where the accumulated
    opacity under ``tf`` reaches ``VISIBLE_OPACITY`` (without ``tf``: where the ray enters the mesh), in the part
    ``clip`` keeps (a renderer that clips in its shader draws the uncut mesh), with its interpolated value,
    tetrahedron (``cell``) and nearest vertex (``point``); None when nothing visible is hit."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    ids, t_in, t_out = _ray_spans(mesh.points, mesh.tets, o, d)
    kept = clip_span(o, d, clip, (0.0, np.inf))
    if kept is None:
        return None
    t_in, t_out = np.maximum(t_in, kept[0]), np.minimum(t_out, kept[1])
    ids, t_in, t_out = ids[t_out > t_in], t_in[t_out > t_in], t_out[t_out > t_in]
    if not len(ids):
        return None
    order = np.argsort(t_in, kind="stable")
    depth_needed = -np.log1p(-VISIBLE_OPACITY)
    depth = 0.0
    for cell, t0, t1 in zip(ids[order], t_in[order], t_out[order]):
        cell = int(cell)
        if tf is None:
            return _result(mesh, component, cell, o + t0 * d)
        s0, s1 = tet_value(mesh, cell, o + t0 * d), tet_value(mesh, cell, o + t1 * d)
        dt = (t1 - t0) / SUBSTEPS
        mid = (np.arange(SUBSTEPS) + 0.5) / SUBSTEPS
        _, rho = tf.evaluate(s0 + (s1 - s0) * mid)
        rho = np.asarray(rho, dtype=np.float64) * float(opacity)
        reached = depth + np.cumsum(rho * dt)
        if reached[-1] >= depth_needed:
            k = int(np.argmax(reached >= depth_needed))
            before = depth + (reached[k - 1] - depth if k else 0.0)
            t = t0 + k * dt + (depth_needed - before) / rho[k]
            return _result(mesh, component, cell, o + min(t, t1) * d)
        depth = float(reached[-1])
    return None


def _result(mesh: Any, component: str, cell: int, x: np.ndarray) -> ProbeResult:
    tet = mesh.tets[cell]
    nearest = int(tet[np.argmin(np.linalg.norm(mesh.points[tet] - x, axis=1))])
    return ProbeResult(component, tet_value(mesh, cell, x), tuple(float(v) for v in x),  # type: ignore[arg-type]
                       cell=cell, point=nearest)
