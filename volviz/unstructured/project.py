"""Shirley-Tuchman classification of projected tetrahedra (Roettger §8.2, Fig. 8.1; Guthe §4.2, Fig. 3.1) and the
classic triangle-based PT rasteriser ("pt-st") that interpolates (s_f, s_b, l) linearly from the thick vertex.

Classes (pixel coordinates of the four projected vertices):

- class 1: one vertex projects inside the triangle of the other three -> 3 triangles around that (thick) vertex;
- class 2: the silhouette is a quadrilateral whose diagonals (the projections of two opposite edges) cross -> 4
  triangles around the crossing point;
- degenerate: a vertex projects onto an edge of the others' triangle (class 1 with one empty triangle: 2 triangles),
  two vertices project onto the same point, or the whole tetrahedron is edge-on / face-on (zero projected area:
  0 triangles, it covers no pixel centre with positive thickness).

The thick vertex carries (s_f, s_b, l) of the ray through it, computed exactly with the same per-pixel ray clipping as
the fast rasteriser (so it is right under perspective too); silhouette vertices carry l = 0 and s_f = s_b = s_vertex.
Interpolating these linearly in screen space is exact for parallel projection (Roettger §8.4) and an approximation
under perspective (digest §15.2 item 7); ``render(..., method="pt")`` instead evaluates them per pixel.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from volviz.unstructured.raster import _lookup

CLASS_DEGENERATE, CLASS_1, CLASS_2 = 0, 1, 2


@njit(cache=True, nogil=True, inline="always")
def _orient(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(cache=True, nogil=True)
def _segment_at(cq: np.ndarray, rb: np.ndarray, near: float, far: float, px: float, py: float
                ) -> tuple[bool, float, float, float]:
    """Exact (s_f, s_b, l) of the pixel ray at continuous pixel position (px, py) through one projected cell."""
    t0 = near
    t1 = far
    for f in range(4):
        b = 6 * f
        num = cq[b] + px * cq[b + 1] + py * cq[b + 2]
        den = cq[b + 3] + px * cq[b + 4] + py * cq[b + 5]
        if abs(den) <= 1e-12:                           # ray in the face plane (thick vertex on an edge-on face)
            if num < -1e-9 * (1.0 + abs(cq[b])):
                return False, 0.0, 0.0, 0.0
        elif den > 0.0:
            t1 = min(t1, num / den)
        else:
            t0 = max(t0, num / den)
    if t1 < t0:
        t1 = t0
    sa = cq[24] + px * cq[25] + py * cq[26]
    sb = cq[27] + px * cq[28] + py * cq[29]
    d0 = rb[3, 0] + px * rb[4, 0] + py * rb[5, 0]
    d1 = rb[3, 1] + px * rb[4, 1] + py * rb[5, 1]
    d2 = rb[3, 2] + px * rb[4, 2] + py * rb[5, 2]
    return True, sa + t0 * sb, sa + t1 * sb, (t1 - t0) * math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit(cache=True, nogil=True)
def shirley_tuchman(vxy: np.ndarray, coef: np.ndarray, svert: np.ndarray, rb: np.ndarray, near: float, far: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Classify every projected cell and split it into triangles.

    ``vxy`` (k, 8) projected vertices, ``coef`` (k, 30) from ``raster.project_cells``, ``svert`` (k, 4) vertex scalars.
    Returns ``cls`` (k,), ``ntri`` (k,), ``tri_xy`` (k, 4, 3, 2) and ``tri_val`` (k, 4, 3, 3) = (s_f, s_b, l) per
    triangle vertex; triangle vertex 0 is the thick vertex.
    """
    k = len(vxy)
    cls = np.zeros(k, np.int64)
    ntri = np.zeros(k, np.int64)
    txy = np.zeros((k, 4, 3, 2))
    tval = np.zeros((k, 4, 3, 3))
    for q in range(k):
        v = vxy[q]
        if v[0] != v[0]:
            continue                                   # crosses the near plane: not projectable as triangles
        scale = 0.0
        for a in range(8):
            scale = max(scale, abs(v[a]))
        eps = 1e-12 * max(scale, 1.0) ** 2
        thick = -1
        tx = 0.0
        ty = 0.0
        outer = np.empty(4, np.int64)
        n_outer = 0
        # class 1: a vertex inside (or on) the triangle of the other three
        for i in range(4):
            j, kk, l_ = (i + 1) % 4, (i + 2) % 4, (i + 3) % 4
            area = _orient(v[2 * j], v[2 * j + 1], v[2 * kk], v[2 * kk + 1], v[2 * l_], v[2 * l_ + 1])
            if abs(area) <= eps:
                continue
            o1 = _orient(v[2 * j], v[2 * j + 1], v[2 * kk], v[2 * kk + 1], v[2 * i], v[2 * i + 1]) / area
            o2 = _orient(v[2 * kk], v[2 * kk + 1], v[2 * l_], v[2 * l_ + 1], v[2 * i], v[2 * i + 1]) / area
            o3 = _orient(v[2 * l_], v[2 * l_ + 1], v[2 * j], v[2 * j + 1], v[2 * i], v[2 * i + 1]) / area
            if o1 >= -1e-12 and o2 >= -1e-12 and o3 >= -1e-12:
                thick = i
                tx, ty = v[2 * i], v[2 * i + 1]
                outer[0], outer[1], outer[2] = j, kk, l_
                n_outer = 3
                break
        if thick < 0:
            # class 2: two opposite edges cross
            for pair in range(3):
                if pair == 0:
                    a, b, c, d = 0, 1, 2, 3
                elif pair == 1:
                    a, b, c, d = 0, 2, 1, 3
                else:
                    a, b, c, d = 0, 3, 1, 2
                ax, ay, bx, by = v[2 * a], v[2 * a + 1], v[2 * b], v[2 * b + 1]
                cx, cy, dx, dy = v[2 * c], v[2 * c + 1], v[2 * d], v[2 * d + 1]
                den = (bx - ax) * (dy - cy) - (by - ay) * (dx - cx)
                if abs(den) <= eps:
                    continue
                u = ((cx - ax) * (dy - cy) - (cy - ay) * (dx - cx)) / den
                w = ((cx - ax) * (by - ay) - (cy - ay) * (bx - ax)) / den
                if 0.0 < u < 1.0 and 0.0 < w < 1.0:
                    thick = 4
                    tx, ty = ax + u * (bx - ax), ay + u * (by - ay)
                    outer[0], outer[1], outer[2], outer[3] = a, c, b, d      # silhouette order around the crossing
                    n_outer = 4
                    break
        if thick < 0:
            continue                                    # zero projected area: edge-on / face-on
        cls[q] = CLASS_1 if n_outer == 3 else CLASS_2
        ok, sf, sb, ln = _segment_at(coef[q], rb, near, far, tx, ty)
        if not ok:
            sf = sb = svert[q, thick] if thick < 4 else 0.0
            ln = 0.0
        nt = 0
        for e in range(n_outer):
            p1 = outer[e]
            p2 = outer[(e + 1) % n_outer]
            area = _orient(tx, ty, v[2 * p1], v[2 * p1 + 1], v[2 * p2], v[2 * p2 + 1])
            if abs(area) <= eps:
                continue                                # degenerate (vertex on an edge): this triangle is empty
            txy[q, nt, 0, 0], txy[q, nt, 0, 1] = tx, ty
            txy[q, nt, 1, 0], txy[q, nt, 1, 1] = v[2 * p1], v[2 * p1 + 1]
            txy[q, nt, 2, 0], txy[q, nt, 2, 1] = v[2 * p2], v[2 * p2 + 1]
            tval[q, nt, 0, 0], tval[q, nt, 0, 1], tval[q, nt, 0, 2] = sf, sb, ln
            tval[q, nt, 1, 0] = tval[q, nt, 1, 1] = svert[q, p1]
            tval[q, nt, 2, 0] = tval[q, nt, 2, 1] = svert[q, p2]
            nt += 1
        ntri[q] = nt
        if nt < n_outer:
            cls[q] = CLASS_DEGENERATE                   # a vertex on an edge / two vertices on one point
    return cls, ntri, txy, tval


@njit(cache=True, nogil=True)
def raster_triangles(ntri: np.ndarray, txy: np.ndarray, tval: np.ndarray, table: np.ndarray, s_lo: float, ds: float,
                     dl: float, width: int, height: int, image: np.ndarray) -> int:
    """Classic PT: triangles in back-to-front cell order, (s_f, s_b, l) interpolated linearly in screen space, table
    lookup, premultiplied "over" (C = C_seg + (1 - a_seg) C). Pixel centres on a shared edge are drawn once
    (top-left rule). Returns the number of fragments."""
    flat = table.ravel()
    n_s = table.shape[0]
    n_l = table.shape[2]
    nf = 0
    for q in range(len(ntri)):
        for t in range(ntri[q]):
            x0, y0 = txy[q, t, 0, 0], txy[q, t, 0, 1]
            x1, y1 = txy[q, t, 1, 0], txy[q, t, 1, 1]
            x2, y2 = txy[q, t, 2, 0], txy[q, t, 2, 1]
            area = _orient(x0, y0, x1, y1, x2, y2)
            if area == 0.0:
                continue
            sgn = 1.0 if area > 0 else -1.0
            c0 = max(int(math.ceil(min(x0, min(x1, x2)))), 0)
            c1 = min(int(math.floor(max(x0, max(x1, x2)))), width - 1)
            r0 = max(int(math.ceil(min(y0, min(y1, y2)))), 0)
            r1 = min(int(math.floor(max(y0, max(y1, y2)))), height - 1)
            for py in range(r0, r1 + 1):
                for px in range(c0, c1 + 1):
                    w0 = sgn * _orient(x1, y1, x2, y2, px, py)
                    w1 = sgn * _orient(x2, y2, x0, y0, px, py)
                    w2 = sgn * _orient(x0, y0, x1, y1, px, py)
                    if w0 < 0 or w1 < 0 or w2 < 0:
                        continue
                    if (w0 == 0 and not _top_left(x1, y1, x2, y2, sgn)) or \
                            (w1 == 0 and not _top_left(x2, y2, x0, y0, sgn)) or \
                            (w2 == 0 and not _top_left(x0, y0, x1, y1, sgn)):
                        continue
                    a = abs(area)
                    b0, b1, b2 = w0 / a, w1 / a, w2 / a
                    sf = b0 * tval[q, t, 0, 0] + b1 * tval[q, t, 1, 0] + b2 * tval[q, t, 2, 0]
                    sb = b0 * tval[q, t, 0, 1] + b1 * tval[q, t, 1, 1] + b2 * tval[q, t, 2, 1]
                    ln = b0 * tval[q, t, 0, 2] + b1 * tval[q, t, 1, 2] + b2 * tval[q, t, 2, 2]
                    r, g, b, al = _lookup(flat, n_s, n_l, s_lo, 1.0 / ds, 1.0 / dl, sf, sb, ln)
                    image[py, px, 0] = r + (1.0 - al) * image[py, px, 0]
                    image[py, px, 1] = g + (1.0 - al) * image[py, px, 1]
                    image[py, px, 2] = b + (1.0 - al) * image[py, px, 2]
                    image[py, px, 3] = al + (1.0 - al) * image[py, px, 3]
                    nf += 1
    return nf


@njit(cache=True, nogil=True, inline="always")
def _top_left(ax, ay, bx, by, sgn):
    """Top-left fill rule for the edge a -> b of a triangle with orientation sign ``sgn`` (y grows downwards)."""
    dx = (bx - ax) * sgn
    dy = (by - ay) * sgn
    return (dy == 0.0 and dx > 0.0) or dy < 0.0
