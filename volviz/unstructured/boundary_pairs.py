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
  by the number of faces; the depth of both planes at a point of the overlap says which is in front. An exit face in
  front of an entry face gives "cell of the entry face before cell of the exit face".

Each relation holds along a real ray, so it is one a correct order obeys; together with MPVO's they order every pair
of cells met consecutively along any ray of the view (not only the pixel centres of one window), so the order serves
any window size. A ray meeting exit, entry, exit, entry faces also yields the non-consecutive pair (first exit, last
entry), which is implied and harmless.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from volviz.model.camera import Camera
from volviz.unstructured.topology import FACES, Topology

#: a boundary face is on the hull when no hull vertex lies farther than this (relative to the mesh extent) outside its
#: plane (the test ``is_convex`` has always used)
HULL_REL_TOL = 1e-9


def inner_boundary(topo: Topology) -> np.ndarray:
    """Indices into ``topo.boundary`` of the boundary faces not on the convex hull (empty: the mesh is convex and
    connected). Cached on ``topo``."""
    cached = topo.__dict__.get("_inner_boundary")
    if cached is not None:
        return cached
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
    topo.__dict__["_inner_boundary"] = inner
    return inner


@njit(cache=True, nogil=True, inline="always")
def _cross(ax: float, ay: float, bx: float, by: float, px: float, py: float) -> float:
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax)


@njit(cache=True, nogil=True)
def _clip_convex(sx: np.ndarray, sy: np.ndarray, ns: int, cx: np.ndarray, cy: np.ndarray, nc: int, eps: float,
                 tx: np.ndarray, ty: np.ndarray) -> int:
    """Sutherland-Hodgman: the counter-clockwise polygon (sx, sy)[:ns] clipped by the counter-clockwise convex
    polygon (cx, cy)[:nc], an edge's outside starting ``eps`` beyond it. Result in (sx, sy); returns its count."""
    for e in range(nc):
        if ns == 0:
            return 0
        ax, ay = cx[e], cy[e]
        bx, by = cx[(e + 1) % nc], cy[(e + 1) % nc]
        tol = eps * np.sqrt((bx - ax) ** 2 + (by - ay) ** 2)
        nt = 0
        for i in range(ns):
            j = (i + 1) % ns
            di = _cross(ax, ay, bx, by, sx[i], sy[i]) + tol
            dj = _cross(ax, ay, bx, by, sx[j], sy[j]) + tol
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
def _pair_relations(px: np.ndarray, py: np.ndarray, nv: np.ndarray, box: np.ndarray, vid: np.ndarray,
                    plane: np.ndarray, entry: np.ndarray, cell: np.ndarray, parallel: bool, extent: np.ndarray,
                    m: int) -> np.ndarray:
    """Keys ``B * m + A`` (B before A) of every overlapping (exit A in front, entry B behind) face pair, found through
    a uniform grid over ``extent`` (x0, x1, y0, y1) with about two bins per face."""
    k = len(nv)
    x0, x1, y0, y1 = extent[0], extent[1], extent[2], extent[3]
    eps = 1e-10 * max(x1 - x0, y1 - y0)
    gx = max(1, int(np.sqrt(2.0 * k * (x1 - x0) / (y1 - y0))))
    gy = max(1, int(2.0 * k / gx))
    sx, sy = gx / (x1 - x0), gy / (y1 - y0)
    lo = np.empty((k, 2), np.int64)
    hi = np.empty((k, 2), np.int64)
    cnt = np.zeros(gx * gy + 1, np.int64)
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
                cnt[cy * gx + cx + 1] += 1
    for c in range(gx * gy):
        cnt[c + 1] += cnt[c]
    fill = cnt[:-1].copy()
    items = np.empty(cnt[-1], np.int64)
    for i in range(k):
        for cy in range(lo[i, 1], hi[i, 1] + 1):
            for cx in range(lo[i, 0], hi[i, 0] + 1):
                items[fill[cy * gx + cx]] = i
                fill[cy * gx + cx] += 1
    sxp, syp = np.empty(16), np.empty(16)
    tx, ty = np.empty(16), np.empty(16)
    out = np.empty(max(16, 4 * k), np.int64)
    n_out = 0
    for c in range(gx * gy):
        ccx, ccy = c % gx, c // gx
        for p in range(cnt[c], cnt[c + 1]):
            a = items[p]
            for q in range(p + 1, cnt[c + 1]):
                b = items[q]
                if entry[a] == entry[b] or cell[a] == cell[b]:
                    continue
                # the pair is handled in the bin of the low corner of the overlap of the two boxes' bin ranges
                if max(lo[a, 0], lo[b, 0]) != ccx or max(lo[a, 1], lo[b, 1]) != ccy:
                    continue
                if (box[a, 0] > box[b, 1] + eps or box[b, 0] > box[a, 1] + eps or box[a, 2] > box[b, 3] + eps
                        or box[b, 2] > box[a, 3] + eps):
                    continue
                shared = False
                for u in range(3):
                    for v in range(3):
                        shared = shared or vid[a, u] == vid[b, v]
                na = nv[a]
                for u in range(na):
                    sxp[u], syp[u] = px[a, u], py[a, u]
                n = _clip_convex(sxp, syp, na, px[b], py[b], nv[b], -eps if shared else eps, tx, ty)
                if n == 0:
                    continue
                wx, wy = sxp[:n].mean(), syp[:n].mean()
                if shared:
                    area = 0.0
                    for u in range(n):
                        area += sxp[u] * syp[(u + 1) % n] - sxp[(u + 1) % n] * syp[u]
                    if area <= eps * eps:
                        continue
                ta = _depth(plane, a, wx, wy, parallel)
                tb = _depth(plane, b, wx, wy, parallel)
                ex, en = (a, b) if not entry[a] else (b, a)
                t_ex, t_en = (ta, tb) if ex == a else (tb, ta)
                if t_ex < t_en:
                    if n_out == len(out):
                        grown = np.empty(2 * len(out), np.int64)
                        grown[:n_out] = out
                        out = grown
                    out[n_out] = cell[en] * m + cell[ex]
                    n_out += 1
    return out[:n_out]


def _inner_faces(topo: Topology) -> tuple[np.ndarray, ...] | None:
    """Per inner boundary face (cached on ``topo``): its cell, vertex ids, corners (k, 3, 3), normal and offset."""
    cached = topo.__dict__.get("_inner_faces")
    if cached is None:
        inner = inner_boundary(topo)
        if len(inner) == 0:
            cached = ()
        else:
            bf = topo.boundary[inner]
            vid = np.ascontiguousarray(topo.tets[bf[:, 0][:, None], FACES[bf[:, 1]]])
            cached = (np.ascontiguousarray(bf[:, 0]), vid, topo.points[vid], topo.face_n[bf[:, 0], bf[:, 1]],
                      topo.face_d[bf[:, 0], bf[:, 1]])
        topo.__dict__["_inner_faces"] = cached
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
