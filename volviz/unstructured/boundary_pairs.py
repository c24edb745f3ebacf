"""Boundary-face relations of a non-convex tetrahedral mesh in object space, at a cost that does not depend on the
window size (issue #29; the object-space XMPVO of Silva, Williams and Comba, restricted as below).

MPVO orders cells that share a face; a non-convex (or disconnected) mesh also needs, along every ray, the pair of cells
where the ray leaves the mesh (exit face of cell A) and re-enters it later (entry face of cell B): "B before A".

- Only boundary faces that do not lie on the convex hull of the mesh can take part (``inner_boundary``): a ray that
  leaves through a face on a supporting plane of the hull is outside the hull from then on, and one that enters
  through such a face was outside the hull before. For the Blunt Fin that is 2,494 of 13,514 boundary faces.
- Per view, every inner face is clipped to the near plane and projected (x/z, y/z; parallel: x, y). Pairs of an exit
  and an entry face whose projections overlap (or touch, within 1e-10 of the view's extent; faces sharing a vertex
  must overlap with positive area) are found through a uniform grid over the visible part of the image plane, sized
  by the number of faces (in each bin only exit against entry faces); the depth of both planes at a point of the
  overlap says which is in front. An exit face in front of an entry face gives "cell of the entry face before cell of
  the exit face". The overlap tests (a polygon clip each) are split over the cores when there are many (a mesh of
  millions of cells).

Each relation holds along a real ray, so it is one a correct order obeys; together with MPVO's they order every pair
of cells met consecutively along any ray of the view (not only the pixel centres of one window), so the order serves
any window size. A ray meeting exit, entry, exit, entry faces also yields the non-consecutive pair (first exit, last
entry), which is implied and harmless.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from volviz.model.camera import Camera
from volviz.unstructured.topology import FACES, Topology

#: a boundary face is on the hull when no hull vertex lies farther than this (relative to the mesh extent) outside its
#: plane (the test ``is_convex`` has always used)
HULL_REL_TOL = 1e-9
#: candidate face pairs from which their overlap tests are split over the cores (the Blunt Fin has about 5,000; its
#: 2.27 M-cell refinement 56,000)
PARALLEL_PAIRS = 20_000


def inner_boundary(topo: Topology) -> np.ndarray:
    """Indices into ``topo.boundary`` of the boundary faces not on the convex hull (empty: the mesh is convex and
    connected). Kept in ``topo.inner_boundary_faces``."""
    cached = topo.inner_boundary_faces
    if cached is not None:
        return cached
    # heavy: SciPy's spatial (Qhull, about 230 modules), loaded only when boundary pairs are found
    from scipy.spatial import ConvexHull, QhullError

    bf = topo.boundary
    inner = np.empty(0, np.int64)
    if len(bf):
        verts = np.unique(topo.tets[bf[:, 0][:, None], FACES[bf[:, 1]]])
        try:
            hull_pts = topo.points[verts][ConvexHull(topo.points[verts]).vertices]
        except QhullError:      # all points in one plane (or fewer than 4): no volume, so no order can be wrong
            hull_pts = None
        if hull_pts is not None:
            scale = float(np.abs(topo.points).max()) or 1.0
            n = topo.face_n[bf[:, 0], bf[:, 1]]
            d = topo.face_d[bf[:, 0], bf[:, 1]]
            out = np.concatenate([(n[s:s + 4096] @ hull_pts.T - d[s:s + 4096, None]).max(axis=1)
                                  for s in range(0, len(n), 4096)])
            inner = np.flatnonzero(out > HULL_REL_TOL * scale).astype(np.int64)
    topo.inner_boundary_faces = inner
    return inner


@njit(cache=True, nogil=True)
def _edge_lines(px: np.ndarray, py: np.ndarray, nv: np.ndarray) -> np.ndarray:
    """Per projected face and edge (counter-clockwise): the unit inward normal and offset (nx, ny, c), so that
    nx * x + ny * y + c is the distance of (x, y) inside the edge's line (all zero for an edge of length 0)."""
    lines = np.zeros((len(nv), 4, 3))
    for i in range(len(nv)):
        n = nv[i]
        for e in range(n):
            ax, ay = px[i, e], py[i, e]
            bx, by = px[i, (e + 1) % n], py[i, (e + 1) % n]
            length = np.sqrt((bx - ax) ** 2 + (by - ay) ** 2)
            if length > 0.0:
                nx, ny = -(by - ay) / length, (bx - ax) / length
                lines[i, e, 0], lines[i, e, 1], lines[i, e, 2] = nx, ny, -(nx * ax + ny * ay)
    return lines


@njit(cache=True, nogil=True, inline="always")
def _clip_convex(sx: np.ndarray, sy: np.ndarray, ns: int, lines: np.ndarray, b: int, nc: int, eps: float,
                 tx: np.ndarray, ty: np.ndarray, dist: np.ndarray) -> int:
    """Sutherland-Hodgman: the polygon (sx, sy)[:ns] clipped by the convex face ``b`` with edge lines
    ``lines[b, :nc]`` (``_edge_lines``), an edge's outside starting ``eps`` beyond it. Result in (sx, sy); returns its
    count."""
    for e in range(nc):
        if ns == 0:
            return 0
        nx, ny, c = lines[b, e, 0], lines[b, e, 1], lines[b, e, 2] + eps
        inside = True
        for i in range(ns):
            dist[i] = nx * sx[i] + ny * sy[i] + c
            inside = inside and dist[i] >= 0.0
        if inside:
            continue
        nt = 0
        for i in range(ns):
            j = i + 1 if i + 1 < ns else 0
            di, dj = dist[i], dist[j]
            if di >= 0.0:
                tx[nt] = sx[i]
                ty[nt] = sy[i]
                nt += 1
            if (di >= 0.0) != (dj >= 0.0):
                w = di / (di - dj)
                tx[nt] = sx[i] + w * (sx[j] - sx[i])
                ty[nt] = sy[i] + w * (sy[j] - sy[i])
                nt += 1
        for i in range(nt):
            sx[i] = tx[i]
            sy[i] = ty[i]
        ns = nt
    return ns


@njit(cache=True, nogil=True)
def _project_faces(view: np.ndarray, near: float, parallel: bool, px: np.ndarray, py: np.ndarray,
                   box: np.ndarray) -> np.ndarray:
    """Each face's triangle (view coordinates, (k, 3, 3)) clipped to z >= near, projected, counter-clockwise, into
    (px, py)[i, :n]; returns n per face (0: wholly in front of the near plane or degenerate); its box in ``box``."""
    k = len(view)
    nv = np.zeros(k, np.int64)
    for i in range(k):
        n = 0
        for a in range(3):
            b = (a + 1) % 3
            za, zb = view[i, a, 2], view[i, b, 2]
            if za >= near:
                px[i, n], py[i, n] = view[i, a, 0], view[i, a, 1]
                if not parallel:
                    px[i, n] /= za
                    py[i, n] /= za
                n += 1
            if (za >= near) != (zb >= near):
                w = (near - za) / (zb - za)
                x = view[i, a, 0] + w * (view[i, b, 0] - view[i, a, 0])
                y = view[i, a, 1] + w * (view[i, b, 1] - view[i, a, 1])
                if not parallel:
                    x /= near
                    y /= near
                px[i, n], py[i, n] = x, y
                n += 1
        area = 0.0
        for a in range(n):
            b = (a + 1) % n
            area += px[i, a] * py[i, b] - px[i, b] * py[i, a]
        if n < 3 or area == 0.0:
            continue
        if area < 0.0:
            for a in range(n // 2):
                px[i, a], px[i, n - 1 - a] = px[i, n - 1 - a], px[i, a]
                py[i, a], py[i, n - 1 - a] = py[i, n - 1 - a], py[i, a]
        box[i, 0], box[i, 1], box[i, 2], box[i, 3] = px[i, 0], px[i, 0], py[i, 0], py[i, 0]
        for a in range(1, n):
            box[i, 0], box[i, 1] = min(box[i, 0], px[i, a]), max(box[i, 1], px[i, a])
            box[i, 2], box[i, 3] = min(box[i, 2], py[i, a]), max(box[i, 3], py[i, a])
        nv[i] = n
    return nv


@njit(cache=True, nogil=True, inline="always")
def _depth(plane: np.ndarray, f: int, wx: float, wy: float, parallel: bool) -> float:
    """Depth along the view of face f's plane on the ray through the image-plane point (wx, wy)."""
    nx, ny, nz, dv = plane[f, 0], plane[f, 1], plane[f, 2], plane[f, 3]
    den = nz if parallel else nx * wx + ny * wy + nz
    if den == 0.0:
        return np.inf
    return (dv - nx * wx - ny * wy) / den if parallel else dv / den


@njit(cache=True, nogil=True)
def _candidates(nv: np.ndarray, box: np.ndarray, entry: np.ndarray, cell: np.ndarray, extent: np.ndarray, eps: float
                ) -> np.ndarray:
    """(exit, entry) face pairs of different cells whose boxes overlap (or touch within ``eps``), each once, found
    through a uniform grid over ``extent`` (x0, x1, y0, y1) with about two bins per face; in each bin the exit faces
    meet only its entry faces, their boxes read in bin order."""
    k = len(nv)
    x0, x1, y0, y1 = extent[0], extent[1], extent[2], extent[3]
    gx = max(1, int(np.sqrt(2.0 * k * (x1 - x0) / (y1 - y0))))
    gy = max(1, int(2.0 * k / gx))
    sx, sy = gx / (x1 - x0), gy / (y1 - y0)
    lo = np.empty((k, 2), np.int64)
    hi = np.empty((k, 2), np.int64)
    cnt = np.zeros(2 * gx * gy + 1, np.int64)          # bin c: exits in slot 2c, entries in slot 2c + 1
    for i in range(k):
        lo[i, 0], hi[i, 0], lo[i, 1], hi[i, 1] = 0, -1, 0, -1
        if nv[i] == 0 or box[i, 1] < x0 - eps or box[i, 0] > x1 + eps or box[i, 3] < y0 - eps or box[i, 2] > y1 + eps:
            continue
        lo[i, 0] = min(max(int((box[i, 0] - eps - x0) * sx), 0), gx - 1)
        hi[i, 0] = min(max(int((box[i, 1] + eps - x0) * sx), 0), gx - 1)
        lo[i, 1] = min(max(int((box[i, 2] - eps - y0) * sy), 0), gy - 1)
        hi[i, 1] = min(max(int((box[i, 3] + eps - y0) * sy), 0), gy - 1)
        for cy in range(lo[i, 1], hi[i, 1] + 1):
            for cx in range(lo[i, 0], hi[i, 0] + 1):
                cnt[2 * (cy * gx + cx) + entry[i] + 1] += 1
    for c in range(2 * gx * gy):
        cnt[c + 1] += cnt[c]
    fill = cnt[:-1].copy()
    items = np.empty(cnt[-1], np.int64)
    for i in range(k):
        for cy in range(lo[i, 1], hi[i, 1] + 1):
            for cx in range(lo[i, 0], hi[i, 0] + 1):
                slot = 2 * (cy * gx + cx) + entry[i]
                items[fill[slot]] = i
                fill[slot] += 1
    ibox = np.empty((len(items), 6))                  # per item: its box and its low bin, in bin order
    for q in range(len(items)):
        i = items[q]
        ibox[q, 0], ibox[q, 1], ibox[q, 2], ibox[q, 3] = box[i, 0], box[i, 1], box[i, 2], box[i, 3]
        ibox[q, 4], ibox[q, 5] = lo[i, 0], lo[i, 1]
    out = np.empty((max(16, 8 * k), 2), np.int64)
    n_out = 0
    for c in range(gx * gy):
        ccx, ccy = c % gx, c // gx
        for p in range(cnt[2 * c], cnt[2 * c + 1]):
            a = items[p]
            ax0, ax1, ay0, ay1 = ibox[p, 0] - eps, ibox[p, 1] + eps, ibox[p, 2] - eps, ibox[p, 3] + eps
            for q in range(cnt[2 * c + 1], cnt[2 * c + 2]):
                # the pair is met in the bin of the low corner of the overlap of the two boxes' bin ranges
                if max(ibox[p, 4], ibox[q, 4]) != ccx or max(ibox[p, 5], ibox[q, 5]) != ccy:
                    continue
                if ibox[q, 0] > ax1 or ibox[q, 1] < ax0 or ibox[q, 2] > ay1 or ibox[q, 3] < ay0:
                    continue
                b = items[q]
                if cell[a] == cell[b]:
                    continue
                if n_out == len(out):
                    grown = np.empty((2 * len(out), 2), np.int64)
                    grown[:n_out] = out
                    out = grown
                out[n_out, 0], out[n_out, 1] = a, b
                n_out += 1
    return out[:n_out]


@njit(cache=True, nogil=True)
def _keys_of(pairs: np.ndarray, lo: int, hi: int, px: np.ndarray, py: np.ndarray, nv: np.ndarray, lines: np.ndarray,
             vid: np.ndarray, plane: np.ndarray, cell: np.ndarray, parallel: bool, eps: float, m: int,
             keys: np.ndarray) -> None:
    """For the (exit A, entry B) pairs ``pairs[lo:hi]``: ``B * m + A`` (B before A) into ``keys`` when their
    projections overlap (faces sharing a vertex: with positive area) and A is in front of B there (the depths of
    both planes at a point of the overlap); else -1."""
    sxp, syp = np.empty(16), np.empty(16)
    tx, ty, dist = np.empty(16), np.empty(16), np.empty(16)
    for i in range(lo, hi):
        keys[i] = -1
        a, b = pairs[i, 0], pairs[i, 1]
        shared = False
        for u in range(3):
            for v in range(3):
                shared = shared or vid[a, u] == vid[b, v]
        f0, f1 = min(a, b), max(a, b)
        for u in range(nv[f0]):
            sxp[u], syp[u] = px[f0, u], py[f0, u]
        n = _clip_convex(sxp, syp, nv[f0], lines, f1, nv[f1], -eps if shared else eps, tx, ty, dist)
        if n == 0:
            continue
        wx, wy, area = 0.0, 0.0, 0.0
        for u in range(n):
            v = u + 1 if u + 1 < n else 0
            wx += sxp[u]
            wy += syp[u]
            area += sxp[u] * syp[v] - sxp[v] * syp[u]
        if shared and area <= eps * eps:
            continue
        wx, wy = wx / n, wy / n
        if _depth(plane, a, wx, wy, parallel) < _depth(plane, b, wx, wy, parallel):
            keys[i] = cell[b] * m + cell[a]


@njit(cache=True, nogil=True, parallel=True)
def _keys_on_cores(pairs: np.ndarray, px: np.ndarray, py: np.ndarray, nv: np.ndarray, lines: np.ndarray,
                   vid: np.ndarray, plane: np.ndarray, cell: np.ndarray, parallel: bool, eps: float, m: int,
                   keys: np.ndarray) -> None:
    n = len(pairs)
    for ch in prange(64):
        _keys_of(pairs, ch * n // 64, (ch + 1) * n // 64, px, py, nv, lines, vid, plane, cell, parallel, eps, m,
                 keys)


def _pair_relations(px: np.ndarray, py: np.ndarray, nv: np.ndarray, box: np.ndarray, vid: np.ndarray,
                    plane: np.ndarray, entry: np.ndarray, cell: np.ndarray, parallel: bool, extent: np.ndarray,
                    m: int) -> np.ndarray:
    """Keys ``B * m + A`` (B before A) of every overlapping (exit A in front, entry B behind) face pair."""
    eps = 1e-10 * max(extent[1] - extent[0], extent[3] - extent[2])
    pairs = _candidates(nv, box, entry, cell, extent, eps)
    lines = _edge_lines(px, py, nv)
    keys = np.empty(len(pairs), np.int64)
    if len(pairs) >= PARALLEL_PAIRS:
        _keys_on_cores(pairs, px, py, nv, lines, vid, plane, cell, parallel, eps, m, keys)
    else:
        _keys_of(pairs, 0, len(pairs), px, py, nv, lines, vid, plane, cell, parallel, eps, m, keys)
    return keys[keys >= 0]


def _inner_faces(topo: Topology) -> tuple[np.ndarray, ...] | None:
    """Per inner boundary face (kept in ``topo.inner_face_planes``): its cell, vertex ids, corners (k, 3, 3), normal
    and offset."""
    cached = topo.inner_face_planes
    if cached is None:
        inner = inner_boundary(topo)
        if len(inner) == 0:
            cached = ()
        else:
            bf = topo.boundary[inner]
            vid = np.ascontiguousarray(topo.tets[bf[:, 0][:, None], FACES[bf[:, 1]]])
            cached = (np.ascontiguousarray(bf[:, 0]), vid, topo.points[vid], topo.face_n[bf[:, 0], bf[:, 1]],
                      topo.face_d[bf[:, 0], bf[:, 1]])
        topo.inner_face_planes = cached
    return cached or None


def object_relations(topo: Topology, cam: Camera, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(src, dst) cell pairs, src drawn before dst, from the inner boundary faces in object space (module docstring).
    ``size`` gives only the image's aspect (the part of the image plane in view); the cost does not depend on it."""
    static = _inner_faces(topo)
    if static is None:
        none = np.empty(0, np.int64)
        return none, none
    cell, vid, corners, n, d = static
    r, u, f = cam.frame()
    rot = np.stack([r, u, f], axis=1)                                           # world -> view: p @ rot
    eye = cam.position - topo.origin
    view = np.ascontiguousarray((corners - eye) @ rot)                          # (k, 3, 3)
    plane = np.empty((len(cell), 4))
    plane[:, :3] = n @ rot
    plane[:, 3] = d - n @ eye                                                   # n_v . p_view = d_v
    if cam.parallel:
        entry, edge_on = plane[:, 2] < 0, plane[:, 2] == 0
    else:
        entry, edge_on = plane[:, 3] < 0, plane[:, 3] == 0
    near = cam.clipping_range[0]
    px, py = np.zeros((len(cell), 4)), np.zeros((len(cell), 4))
    box = np.zeros((len(cell), 4))
    nv = _project_faces(view, near, cam.parallel, px, py, box)
    nv[edge_on] = 0
    w, h = size
    hy = cam.parallel_scale if cam.parallel else np.tan(np.radians(cam.view_angle) / 2.0)
    hx = hy * w / h
    keys = _pair_relations(px, py, nv, box, vid, plane, entry, cell, cam.parallel,
                           np.array([-hx, hx, -hy, hy]), topo.n_tets)
    keys = np.unique(keys)
    return keys // topo.n_tets, keys % topo.n_tets
