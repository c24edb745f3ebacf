"""Numba CPU rasteriser of triangles into per-pixel fragment lists (the CPU stand-in for the note's render passes).

Pixel centres sit at continuous coordinates (col, row) as ``Camera.project`` gives them; coverage uses the top-left
rule, so a pixel on an edge shared by two triangles gets exactly one fragment (no double-counted layers). Depth and
the per-vertex attribute μ = |cos θ| are interpolated perspective-correctly (through 1/z). ``rasterize`` drops
triangles with a vertex at or behind the eye; call :func:`clip_near_plane` first to cut triangles that cross the
near plane, as OpenGL's clipper does (``volviz.iso.composite.fragments`` does). Fragments are written in triangle
(draw) order, which the 2-pass mode relies on.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

__all__ = ["rasterize", "clip_near_plane"]


def clip_near_plane(points: np.ndarray, triangles: np.ndarray, attributes: np.ndarray, eye: np.ndarray,
                    forward: np.ndarray, near: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cut triangles at the near plane ``(x − eye)·forward = near`` and keep the parts beyond it.

    A triangle with one vertex beyond the plane becomes one triangle, with two vertices beyond it a quad split in two
    triangles; the new vertices lie on the plane, their ``attributes`` (n, k) (e.g. normals) linearly interpolated
    along the cut edges (exact for attributes linear over the triangle). Triangles wholly in front are dropped,
    wholly beyond kept unchanged and first, in their order. Returns (points, triangles, attributes, parent index of
    every output triangle)."""
    pts = np.asarray(points, dtype=np.float64)
    tris = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    att = np.asarray(attributes, dtype=np.float64)
    att = att.reshape(len(pts), -1) if att.ndim != 2 else att
    d = (pts - np.asarray(eye, dtype=np.float64)) @ np.asarray(forward, dtype=np.float64) - float(near)
    inside = d[tris] >= 0.0 if len(tris) else np.zeros((0, 3), bool)
    n_in = inside.sum(axis=1)
    keep = np.flatnonzero(n_in == 3)
    cut = np.flatnonzero((n_in == 1) | (n_in == 2))
    if len(cut) == 0:
        return pts, tris[keep], att, keep
    t = tris[cut]
    odd = np.where((n_in[cut] == 1)[:, None], inside[cut], ~inside[cut])  # the lone vertex (in or out)
    first = np.argmax(odd, axis=1)                                           # rotate it to slot 0 (same winding)
    rot = t[np.arange(len(t))[:, None], (first[:, None] + np.arange(3)) % 3]
    v0, v1, v2 = rot[:, 0], rot[:, 1], rot[:, 2]

    def edge(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = (d[a] / (d[a] - d[b]))[:, None]
        return pts[a] + w * (pts[b] - pts[a]), att[a] + w * (att[b] - att[a])

    p01, a01 = edge(v0, v1)
    p02, a02 = edge(v0, v2)
    m = len(cut)
    base = len(pts)
    i01, i02 = base + np.arange(m), base + m + np.arange(m)
    one = n_in[cut] == 1   # v0 beyond the plane: triangle (v0, e01, e02)
    new_tris = [np.stack([v0, i01, i02], axis=1)[one],
                np.stack([i01, v1, v2], axis=1)[~one],  # v0 in front: quad (e01, v1, v2, e02)
                np.stack([i01, v2, i02], axis=1)[~one]]
    parents = [cut[one], cut[~one], cut[~one]]
    out_pts = np.concatenate([pts, p01, p02])
    out_att = np.concatenate([att, a01, a02])
    return (out_pts, np.concatenate([tris[keep]] + new_tris), out_att, np.concatenate([keep] + parents))


@njit(cache=True, nogil=True, inline="always")
def _inside(e: float, dx: float, dy: float) -> bool:
    # top-left rule for a counter-clockwise (positive-area) triangle in (x right, y down) pixel coordinates
    if e > 0.0:
        return True
    if e < 0.0:
        return False
    return (dy < 0.0) or (dy == 0.0 and dx > 0.0)


@njit(cache=True, nogil=True)
def _tri(k: int, sx: np.ndarray, sy: np.ndarray, iz: np.ndarray, att: np.ndarray, tris: np.ndarray, w: int, h: int,
         perspective: bool, write: bool, start: int, pix: np.ndarray, dep: np.ndarray, mu: np.ndarray,
         tid: np.ndarray) -> int:
    i0, i1, i2 = tris[k, 0], tris[k, 1], tris[k, 2]
    x0, y0, x1, y1, x2, y2 = sx[i0], sy[i0], sx[i1], sy[i1], sx[i2], sy[i2]
    area = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)
    if not (abs(area) > 1e-14):
        return 0
    if area < 0.0:  # make the vertex order positive
        i1, i2 = i2, i1
        x1, y1, x2, y2 = x2, y2, x1, y1
        area = -area
    if iz[i0] <= 0.0 or iz[i1] <= 0.0 or iz[i2] <= 0.0:
        return 0
    c0 = max(0, int(np.ceil(min(x0, x1, x2))))
    c1 = min(w - 1, int(np.floor(max(x0, x1, x2))))
    r0 = max(0, int(np.ceil(min(y0, y1, y2))))
    r1 = min(h - 1, int(np.floor(max(y0, y1, y2))))
    n = 0
    inv = 1.0 / area
    for r in range(r0, r1 + 1):
        py = float(r)
        for c in range(c0, c1 + 1):
            px = float(c)
            e0 = (x2 - x1) * (py - y1) - (y2 - y1) * (px - x1)  # opposite vertex 0
            e1 = (x0 - x2) * (py - y2) - (y0 - y2) * (px - x2)
            e2 = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)
            if not (_inside(e0, x2 - x1, y2 - y1) and _inside(e1, x0 - x2, y0 - y2) and _inside(e2, x1 - x0, y1 - y0)):
                continue
            if write:
                b0, b1, b2 = e0 * inv, e1 * inv, e2 * inv
                if perspective:
                    q = b0 * iz[i0] + b1 * iz[i1] + b2 * iz[i2]
                    dep[start + n] = 1.0 / q
                    mu[start + n] = (b0 * iz[i0] * att[i0] + b1 * iz[i1] * att[i1] + b2 * iz[i2] * att[i2]) / q
                else:
                    dep[start + n] = b0 / iz[i0] + b1 / iz[i1] + b2 / iz[i2]
                    mu[start + n] = b0 * att[i0] + b1 * att[i1] + b2 * att[i2]
                pix[start + n] = r * w + c
                tid[start + n] = k
            n += 1
    return n


@njit(cache=True, nogil=True, parallel=True)
def _count(sx, sy, iz, att, tris, w, h, perspective):
    m = tris.shape[0]
    cnt = np.zeros(m, np.int64)
    e_i = np.zeros(0, np.int64)
    e_f = np.zeros(0, np.float64)
    for k in prange(m):
        cnt[k] = _tri(k, sx, sy, iz, att, tris, w, h, perspective, False, 0, e_i, e_f, e_f, e_i)
    return cnt


@njit(cache=True, nogil=True, parallel=True)
def _fill(sx, sy, iz, att, tris, w, h, perspective, off, pix, dep, mu, tid):
    for k in prange(tris.shape[0]):
        _tri(k, sx, sy, iz, att, tris, w, h, perspective, True, off[k], pix, dep, mu, tid)


def rasterize(screen: np.ndarray, attribute: np.ndarray, triangles: np.ndarray, size: tuple[int, int],
              perspective: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fragments of all triangles: (pixel index row·W + col, view depth, interpolated attribute, triangle index).

    ``screen`` is (n, 3) from ``Camera.project`` (px, py, depth); ``attribute`` (n,) is interpolated per fragment.
    """
    w, h = (int(v) for v in size)
    scr = np.asarray(screen, dtype=np.float64)
    sx, sy = np.ascontiguousarray(scr[:, 0]), np.ascontiguousarray(scr[:, 1])
    z = scr[:, 2]
    iz = np.where(z > 0.0, 1.0 / np.where(z > 0.0, z, 1.0), -1.0)
    iz = np.where(np.isfinite(sx) & np.isfinite(sy), iz, -1.0)
    sx, sy = np.nan_to_num(sx), np.nan_to_num(sy)
    att = np.ascontiguousarray(attribute, dtype=np.float64)
    tris = np.ascontiguousarray(triangles, dtype=np.int64).reshape(-1, 3)
    cnt = _count(sx, sy, iz, att, tris, w, h, perspective)
    off = np.zeros(len(cnt) + 1, np.int64)
    np.cumsum(cnt, out=off[1:])
    total = int(off[-1])
    pix, tid = np.empty(total, np.int64), np.empty(total, np.int64)
    dep, mu = np.empty(total, np.float64), np.empty(total, np.float64)
    _fill(sx, sy, iz, att, tris, w, h, perspective, off, pix, dep, mu, tid)
    return pix, dep, mu, tid
