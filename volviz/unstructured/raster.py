"""The fast path "pt": projected tetrahedra with exact per-pixel (s_f, s_b, l) and the 3D pre-integration table,
rasterised and composited on the CPU in Numba (Roettger §8.4, Eq. 8.1; Guthe §4.6 for perspective).

Per tetrahedron (``project_cells``, parallel over cells): its pixel box, and for each face plane n.x = d the affine
forms num(px, py) = d - n.O and den(px, py) = n.D of the pixel ray O + tD, and the affine scalar s(O + tD) = a + t b.
Per pixel (``raster_tiles``) the ray is clipped against the four face half-spaces (t den <= num) and the near/far
planes, giving the exact entry/exit depths t_f < t_b, so s_f = a + t_f b, s_b = a + t_b b and l = (t_b - t_f)|D|.
This is the projected-tetrahedron footprint (the union of the 3 or 4 Shirley-Tuchman triangles, see
``project.shirley_tuchman``) with the per-pixel values that Guthe's vertex/fragment program computes with a
homogeneous divide: it is exact under perspective, where interpolating (s_f, s_b, l) linearly from the thick vertex is
not (Roettger §8.4, digest §15.2 item 7). Segments clipped by the near plane start at t = near (volumetric clipping of
cells around the camera). Rays through shared faces or edges produce zero-length segments in the neighbours, which
contribute nothing, so no fill-convention is needed: no pixel is drawn twice or missed. A ray lying in a face plane
(|n.D| <= 1e-12 |D|, e.g. a grid seen exactly along its planes) is inside when its distance to the plane exceeds
``tol`` and otherwise by the same simulation-of-simplicity tie-break as the reference (displacement by a fixed generic
vector), so the two cells sharing the face do not both draw it (before: 79/255 errors on a grid seen along z).

Compositing is front to back over the reversed visibility order (equivalent to back-to-front "over",
C = C_seg + (1 - a_seg) C_behind), in screen tiles processed in parallel; a tile stops when every pixel's transmittance
is below ``t_min`` (early ray termination; error <= t_min per channel). The segment color comes from the separable
tables (Roettger §9.1: exact opacity 1 - exp(-l rho_hat), color polynomial of degree 2 in l; default, 256^2) or the
3D table (trilinear). The separable tables are the default because they are about 10x more
accurate than the 3D table for about 20 % more raster time (``docs/bench/docstring-figures.md``).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, prange, uint64

from volviz.optics.integrate import _linear_piece

TILE = 32
#: per-cell coefficients: 4 faces x (num0, numx, numy, den0, denx, deny), then scalar (a0, ax, ay, b0, bx, by), then
#: per face +1 / -1: whether a ray lying in the face plane counts as inside (simulation-of-simplicity tie-break)
N_COEF = 34
#: the generic displacement of the tie-break (the same as the reference's)
SOS = np.array([0.5773502691896258, 0.6180339887498949, 0.5335536495417815])
SOS /= np.linalg.norm(SOS)


@njit(cache=True, nogil=True, inline="always")
def _det3(a0, a1, a2, b0, b1, b2, c0, c1, c2):
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0)


@njit(cache=True, nogil=True, parallel=True)
def project_cells(pts: np.ndarray, tets: np.ndarray, scal: np.ndarray, cells: np.ndarray, face_n: np.ndarray,
                  face_d: np.ndarray, rb: np.ndarray, frame: np.ndarray, scales: np.ndarray, parallel: bool,
                  near: float, width: int, height: int, sos: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pixel boxes (k, 4) [c0, c1, r0, r1], coefficients (k, 30) and projected vertices (k, 8) [px0, py0, ...] of
    the listed cells (positions relative); a NaN in the projected vertices marks a cell crossing the near plane."""
    k = len(cells)
    box = np.empty((k, 4), np.int64)
    coef = np.empty((k, N_COEF))
    vxy = np.empty((k, 8))
    for q in prange(k):
        c = cells[q]
        # --- pixel box from the projected vertices; a cell crossing the near plane gets the box of its part in
        # front of it (front vertices and the edges' crossings of the plane), empty if it lies wholly behind it
        xmin, xmax, ymin, ymax = 1e300, -1e300, 1e300, -1e300
        full = False
        cx = np.empty(4)
        cy = np.empty(4)
        cz = np.empty(4)
        for v in range(4):
            iv = tets[c, v]
            rel0 = pts[iv, 0] - frame[3, 0]
            rel1 = pts[iv, 1] - frame[3, 1]
            rel2 = pts[iv, 2] - frame[3, 2]
            cx[v] = rel0 * frame[0, 0] + rel1 * frame[0, 1] + rel2 * frame[0, 2]
            cy[v] = rel0 * frame[1, 0] + rel1 * frame[1, 1] + rel2 * frame[1, 2]
            cz[v] = rel0 * frame[2, 0] + rel1 * frame[2, 1] + rel2 * frame[2, 2]
            if not parallel and cz[v] <= near * (1.0 + 1e-9):
                full = True
        for v in range(4):
            if parallel or cz[v] > near * (1.0 + 1e-9):
                x, y = cx[v], cy[v]
                if not parallel:
                    x /= cz[v]
                    y /= cz[v]
                px = (x / scales[0] + 1.0) * width * 0.5 - 0.5
                py = (1.0 - y / scales[1]) * height * 0.5 - 0.5
                vxy[q, 2 * v] = px
                vxy[q, 2 * v + 1] = py
                xmin, xmax = min(xmin, px), max(xmax, px)
                ymin, ymax = min(ymin, py), max(ymax, py)
        if full:
            for a in range(3):
                for b in range(a + 1, 4):
                    za, zb = cz[a] - near, cz[b] - near
                    if (za > 0.0) == (zb > 0.0):
                        continue
                    w = za / (za - zb)
                    x = (cx[a] + w * (cx[b] - cx[a])) / near
                    y = (cy[a] + w * (cy[b] - cy[a])) / near
                    px = (x / scales[0] + 1.0) * width * 0.5 - 0.5
                    py = (1.0 - y / scales[1]) * height * 0.5 - 0.5
                    xmin, xmax = min(xmin, px), max(xmax, px)
                    ymin, ymax = min(ymin, py), max(ymax, py)
            vxy[q, 0] = np.nan
        if xmin > xmax:                 # wholly behind the near plane: nothing to draw
            box[q, 0], box[q, 1], box[q, 2], box[q, 3] = 0, -1, 0, -1
        else:
            box[q, 0] = max(int(math.floor(xmin)) - 1, 0) if full else max(int(math.floor(xmin)), 0)
            box[q, 1] = min(int(math.ceil(xmax)) + 1, width - 1) if full else min(int(math.ceil(xmax)), width - 1)
            box[q, 2] = max(int(math.floor(ymin)) - 1, 0) if full else max(int(math.floor(ymin)), 0)
            box[q, 3] = min(int(math.ceil(ymax)) + 1, height - 1) if full else min(int(math.ceil(ymax)), height - 1)
        # --- face half-spaces as affine forms of (px, py)
        for f in range(4):
            n0, n1, n2 = face_n[c, f, 0], face_n[c, f, 1], face_n[c, f, 2]
            b = 6 * f
            coef[q, b + 0] = face_d[c, f] - (n0 * rb[0, 0] + n1 * rb[0, 1] + n2 * rb[0, 2])
            coef[q, b + 1] = -(n0 * rb[1, 0] + n1 * rb[1, 1] + n2 * rb[1, 2])
            coef[q, b + 2] = -(n0 * rb[2, 0] + n1 * rb[2, 1] + n2 * rb[2, 2])
            coef[q, b + 3] = n0 * rb[3, 0] + n1 * rb[3, 1] + n2 * rb[3, 2]
            coef[q, b + 4] = n0 * rb[4, 0] + n1 * rb[4, 1] + n2 * rb[4, 2]
            coef[q, b + 5] = n0 * rb[5, 0] + n1 * rb[5, 1] + n2 * rb[5, 2]
            coef[q, 30 + f] = 1.0 if n0 * sos[0] + n1 * sos[1] + n2 * sos[2] < 0.0 else -1.0
        # --- scalar gradient g (E g = ds, Cramer's rule) and s(x) = s0 + g.x
        i0, i1, i2, i3 = tets[c, 0], tets[c, 1], tets[c, 2], tets[c, 3]
        a0, a1, a2 = pts[i1, 0] - pts[i0, 0], pts[i1, 1] - pts[i0, 1], pts[i1, 2] - pts[i0, 2]
        b0, b1, b2 = pts[i2, 0] - pts[i0, 0], pts[i2, 1] - pts[i0, 1], pts[i2, 2] - pts[i0, 2]
        c0, c1, c2 = pts[i3, 0] - pts[i0, 0], pts[i3, 1] - pts[i0, 1], pts[i3, 2] - pts[i0, 2]
        d0, d1, d2 = scal[i1] - scal[i0], scal[i2] - scal[i0], scal[i3] - scal[i0]
        det = _det3(a0, a1, a2, b0, b1, b2, c0, c1, c2)
        g0 = g1 = g2 = 0.0
        if det != 0.0:
            g0 = _det3(d0, a1, a2, d1, b1, b2, d2, c1, c2) / det
            g1 = _det3(a0, d0, a2, b0, d1, b2, c0, d2, c2) / det
            g2 = _det3(a0, a1, d0, b0, b1, d1, c0, c1, d2) / det
        s0 = scal[i0] - (g0 * pts[i0, 0] + g1 * pts[i0, 1] + g2 * pts[i0, 2])
        coef[q, 24] = s0 + g0 * rb[0, 0] + g1 * rb[0, 1] + g2 * rb[0, 2]
        coef[q, 25] = g0 * rb[1, 0] + g1 * rb[1, 1] + g2 * rb[1, 2]
        coef[q, 26] = g0 * rb[2, 0] + g1 * rb[2, 1] + g2 * rb[2, 2]
        coef[q, 27] = g0 * rb[3, 0] + g1 * rb[3, 1] + g2 * rb[3, 2]
        coef[q, 28] = g0 * rb[4, 0] + g1 * rb[4, 1] + g2 * rb[4, 2]
        coef[q, 29] = g0 * rb[5, 0] + g1 * rb[5, 1] + g2 * rb[5, 2]
    return box, coef, vxy


@njit(cache=True, nogil=True, inline="always")
def _row_span(v: np.ndarray, py: float) -> tuple[float, float]:
    """x-extent at row py of the convex hull of the 4 projected vertices (span of its 6 edges' crossings)."""
    lo = 1e300
    hi = -1e300
    for a in range(3):
        for b in range(a + 1, 4):
            xa, ya, xb, yb = v[2 * a], v[2 * a + 1], v[2 * b], v[2 * b + 1]
            if ya > yb:
                xa, ya, xb, yb = xb, yb, xa, ya
            if py < ya or py > yb:
                continue
            if yb > ya:
                x = xa + (py - ya) * (xb - xa) / (yb - ya)
                lo = min(lo, x)
                hi = max(hi, x)
            else:
                lo = min(lo, min(xa, xb))
                hi = max(hi, max(xa, xb))
    return lo, hi


@njit(cache=True, nogil=True)
def bin_tiles(box: np.ndarray, width: int, height: int, tile: int) -> tuple[np.ndarray, np.ndarray]:
    """Tile lists in draw order: CSR (ptr, items) where items are indices into ``box`` (back to front)."""
    tx = (width + tile - 1) // tile
    ty = (height + tile - 1) // tile
    ptr = np.zeros(tx * ty + 1, np.int64)
    for q in range(len(box)):
        if box[q, 0] > box[q, 1] or box[q, 2] > box[q, 3]:
            continue
        for j in range(box[q, 2] // tile, box[q, 3] // tile + 1):
            for i in range(box[q, 0] // tile, box[q, 1] // tile + 1):
                ptr[j * tx + i + 1] += 1
    for t in range(tx * ty):
        ptr[t + 1] += ptr[t]
    pos = ptr[:-1].copy()
    items = np.empty(ptr[-1], np.int64)
    for q in range(len(box)):
        if box[q, 0] > box[q, 1] or box[q, 2] > box[q, 3]:
            continue
        for j in range(box[q, 2] // tile, box[q, 3] // tile + 1):
            for i in range(box[q, 0] // tile, box[q, 1] // tile + 1):
                t = j * tx + i
                items[pos[t]] = q
                pos[t] += 1
    return ptr, items


@njit(cache=True, nogil=True, inline="always")
def _bin(x: float, inv_step: float, n: int) -> tuple[int, float]:
    """Table cell and weight of x (in table units after * inv_step), clamped to [0, n - 1]."""
    f = min(max(x * inv_step, 0.0), n - 1.0)
    i = min(int(f), n - 2)
    return i, f - i


@njit(cache=True, nogil=True, inline="always")
def _bilinear_weights(wi: float, wj: float) -> tuple[float, float, float, float]:
    return (1.0 - wi) * (1.0 - wj), (1.0 - wi) * wj, wi * (1.0 - wj), wi * wj


@njit(cache=True, nogil=True, inline="always")
def _lookup(flat: np.ndarray, n: int, nl: int, s_lo: float, inv_ds: float, inv_dl: float, sf: float, sb: float,
            ln: float) -> tuple[float, float, float, float]:
    """Trilinear lookup in the flattened (n, n, nl, 4) table; scalars clamp to the table, l clamps to l_max."""
    i, wi = _bin(sf - s_lo, inv_ds, n)
    j, wj = _bin(sb - s_lo, inv_ds, n)
    k, wk = _bin(ln, inv_dl, nl)
    w00, w01, w10, w11 = _bilinear_weights(wi, wj)
    sj = uint64(nl * 4)
    si = uint64(n) * sj
    b = uint64(i) * si + uint64(j) * sj + uint64(k * 4)
    r0 = 0.0
    r1 = 0.0
    r2 = 0.0
    r3 = 0.0
    for corner in range(4):
        if corner == 0:
            o, w = b, w00
        elif corner == 1:
            o, w = b + sj, w01
        elif corner == 2:
            o, w = b + si, w10
        else:
            o, w = b + si + sj, w11
        wa = w * (1.0 - wk)
        wb = w * wk
        r0 += wa * flat[o] + wb * flat[o + uint64(4)]
        r1 += wa * flat[o + uint64(1)] + wb * flat[o + uint64(5)]
        r2 += wa * flat[o + uint64(2)] + wb * flat[o + uint64(6)]
        r3 += wa * flat[o + uint64(3)] + wb * flat[o + uint64(7)]
    return r0, r1, r2, r3


@njit(cache=True, nogil=True, inline="always")
def _lookup_separable(flat: np.ndarray, n: int, nc: int, deg: int, s_lo: float, inv_ds: float, inv_lmax: float,
                      k0: float, k1: float, k2: float, sf: float, sb: float, ln: float
                      ) -> tuple[float, float, float, float]:
    """Separable pre-integration (Roettger §9.1): bilinear rho_hat and color coefficients in (s_f, s_b),
    a = 1 - exp(-l rho_hat) (exact in l), color = a clamp(sum_i C_i u^i), u = l / l_max clamped to [0, 1]."""
    i, wi = _bin(sf - s_lo, inv_ds, n)
    j, wj = _bin(sb - s_lo, inv_ds, n)
    w00, w01, w10, w11 = _bilinear_weights(wi, wj)
    # unsigned offsets: no negative-index wraparound code in the hot loop
    b00 = uint64((i * n + j) * nc)
    b01 = b00 + uint64(nc)
    b10 = b00 + uint64(n * nc)
    b11 = b10 + uint64(nc)
    rho = w00 * flat[b00] + w01 * flat[b01] + w10 * flat[b10] + w11 * flat[b11]
    a = -math.expm1(-ln * rho)
    u = min(max(ln * inv_lmax, 0.0), 1.0)
    c0 = 0.0
    c1 = 0.0
    c2 = 0.0
    for d in range(deg, -1, -1):
        o = uint64(1 + 3 * d)
        c0 = c0 * u + (w00 * flat[b00 + o] + w01 * flat[b01 + o] + w10 * flat[b10 + o] + w11 * flat[b11 + o])
        o += uint64(1)
        c1 = c1 * u + (w00 * flat[b00 + o] + w01 * flat[b01 + o] + w10 * flat[b10 + o] + w11 * flat[b11 + o])
        o += uint64(1)
        c2 = c2 * u + (w00 * flat[b00 + o] + w01 * flat[b01 + o] + w10 * flat[b10 + o] + w11 * flat[b11 + o])
    c0 = min(max(c0, 0.0), k0)
    c1 = min(max(c1, 0.0), k1)
    c2 = min(max(c2, 0.0), k2)
    return c0 * a, c1 * a, c2 * a, a


def _widened(table: Any, values: np.ndarray) -> np.ndarray:
    """``values`` as flat float64, converted once per table and kept on it (a 3D table is 32 MB in float64: not
    worth redoing every frame); redone when the table was rebuilt for another TF or its array replaced."""
    tf = getattr(table, "tf", None)
    cached = getattr(table, "_volviz_flat64", None)
    if cached is None or cached[0] is not values or cached[1] is not tf:
        cached = (values, tf, np.ascontiguousarray(values, dtype=np.float64).ravel())
        try:
            table._volviz_flat64 = cached
        except AttributeError:          # tables without an instance dict: convert every time
            pass
    return cached[2]


def lut_args(table: Any, smooth: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(flat float64 data (float32 tables widened once: no conversion per tap), int64 [kind, n_s, n_l or channels,
    degree], float64 [s_lo, 1/ds, 1/dl or 1/l_max, kappa_max (3)]) of a ``Table3D`` (kind 0), a ``SeparableTable``
    (kind 1) or an ``IsoTable`` (kind 2: its isosurfaces evaluated exactly, not its texture) or a ``Preclassified`` TF
    (kind 3: each segment's ends classified exactly, ``_preclassified``) for the raster kernels. ``smooth``: shade
    isosurfaces (kind 2) with the per-pixel intensities the rasteriser interpolates
    (``volviz.unstructured.iso.vertex_shade``)."""
    if hasattr(table, "preclassified_tf"):                  # exact pre-classified segments (kind 3)
        tf = table.preclassified_tf
        flat = np.concatenate([tf.scalars, tf.colors.ravel(), tf.extinction]).astype(np.float64)
        ip = np.array([3, len(tf.scalars), 0, 0], np.int64)
        fp = np.zeros(6)
    elif hasattr(table, "isosurfaces"):                     # exact flat isosurfaces (kind 2)
        isos = sorted(table.isosurfaces, key=lambda i: i.value)
        flat = np.array([[i.value, i.opacity, *i.color, *(i.color if i.back_color is None else i.back_color)]
                         for i in isos], dtype=np.float64).ravel()
        ip = np.array([2, len(isos), 8, 0], np.int64)
        fp = np.array([table.thicken, 1.0 if smooth else 0.0, 0.0, 0.0, 0.0, 0.0])
    elif hasattr(table, "rgba"):
        flat = _widened(table, table.rgba)
        ip = np.array([0, table.rgba.shape[0], table.rgba.shape[2], 0], np.int64)
        fp = np.array([table.s_lo, 1.0 / table.ds, 1.0 / table.dl, 0.0, 0.0, 0.0])
    else:
        flat = _widened(table, table.data)
        ip = np.array([1, table.data.shape[0], table.data.shape[2], table.degree], np.int64)
        k = np.asarray(table.kappa_max, dtype=np.float64)
        fp = np.array([table.s_lo, 1.0 / table.ds, 1.0 / table.l_max, k[0], k[1], k[2]])
    return flat, ip, fp


@njit(cache=True, nogil=True)
def _iso_exact(flat: np.ndarray, n: int, thicken: float, smooth: bool, sf: float, sb: float, hf: float, hb: float
               ) -> tuple[float, float, float, float]:
    """Exact isosurfaces crossed by the segment (Roettger §8.13 Heaviside limit, H(0) = 1/2), front to back;
    ``flat`` holds per surface (ascending values) value, opacity, color (3), back color (3). Flat colors, or with
    ``smooth`` scaled by the shading intensity where the surface is crossed, linear from ``hf`` (front) to ``hb``
    (Roettger §8.9)."""
    lo = min(sf, sb)
    hi = max(sf, sb)
    asc = sb >= sf
    tr = 1.0
    c0 = 0.0
    c1 = 0.0
    c2 = 0.0
    for idx in range(n):
        k = 8 * (idx if asc else n - 1 - idx)
        v = flat[k]
        h = 0.0
        if thicken > 0.0:
            if lo - thicken <= v <= hi + thicken:
                h = 1.0
        elif lo < hi:
            h = (1.0 if lo < v else (0.5 if lo == v else 0.0)) * (1.0 if hi > v else (0.5 if hi == v else 0.0))
        a = h * flat[k + 1]
        if a > 0.0:
            o = k + 2 if asc else k + 5
            shade = 1.0
            if smooth:
                w = min(max((v - sf) / (sb - sf), 0.0), 1.0) if sb != sf else 0.5
                shade = hf + w * (hb - hf)
            c0 += tr * a * flat[o] * shade
            c1 += tr * a * flat[o + 1] * shade
            c2 += tr * a * flat[o + 2] * shade
            tr *= 1.0 - a
    return c0, c1, c2, 1.0 - tr


@njit(cache=True, nogil=True, inline="always")
def _classify(flat: np.ndarray, n: int, s: float) -> tuple[float, float, float, float]:
    """κ (3) and ρ of the TF packed in ``flat`` (scalars, colors, extinction) at s; outside or NaN: zero."""
    if not (flat[0] <= s <= flat[n - 1]):
        return 0.0, 0.0, 0.0, 0.0
    k = min(max(np.searchsorted(flat[:n], s, side="right") - 1, 0), n - 2)
    w = (s - flat[k]) / (flat[k + 1] - flat[k])
    c = n + 3 * k
    e = 4 * n + k
    return (flat[c] + w * (flat[c + 3] - flat[c]), flat[c + 1] + w * (flat[c + 4] - flat[c + 1]),
            flat[c + 2] + w * (flat[c + 5] - flat[c + 2]), flat[e] + w * (flat[e + 1] - flat[e]))


@njit(cache=True, nogil=True)
def _preclassified(flat: np.ndarray, n: int, sf: float, sb: float, ln: float) -> tuple[float, float, float, float]:
    """Pre-classified segment (Roettger §8.14): the TF at both ends, κ and ρ linear in between, integrated in
    closed form (``volviz.optics.integrate_preclassified``, evaluated per pixel without a table)."""
    kf0, kf1, kf2, rf = _classify(flat, n, sf)
    kb0, kb1, kb2, rb = _classify(flat, n, sb)
    out = np.zeros(3)
    et, t = _linear_piece((kf0, kf1, kf2), (kb0, kb1, kb2), 0.0, 1.0, rf * ln, rb * ln, 1.0, out)
    return out[0], out[1], out[2], -math.expm1(-t)


@njit(cache=True, nogil=True, inline="always")
def lookup_any(flat: np.ndarray, ip: np.ndarray, fp: np.ndarray, sf: float, sb: float, ln: float, hf: float = 1.0,
               hb: float = 1.0) -> tuple[float, float, float, float]:
    """Premultiplied RGBA of the segment (s_f, s_b, l) from the table described by ``lut_args`` (``hf``/``hb``:
    shading intensities at the segment's ends, used by smooth isosurfaces)."""
    if ip[0] == 0:
        return _lookup(flat, ip[1], ip[2], fp[0], fp[1], fp[2], sf, sb, ln)
    if ip[0] == 2:
        return _iso_exact(flat, ip[1], fp[0], fp[1] != 0.0, sf, sb, hf, hb)
    if ip[0] == 3:
        return _preclassified(flat, ip[1], sf, sb, ln)
    return _lookup_separable(flat, ip[1], ip[2], ip[3], fp[0], fp[1], fp[2], fp[3], fp[4], fp[5], sf, sb, ln)


@njit(cache=True, nogil=True, inline="always")
def _shade_ends(hq: np.ndarray, x: float, y: float, t0: float, t1: float) -> tuple[float, float]:
    """Shading intensity at the segment's ends from a cell's affine forms ``hq`` (a0, ax, ay, b0, bx, by)."""
    ha = hq[0] + x * hq[1] + y * hq[2]
    hb = hq[3] + x * hq[4] + y * hq[5]
    return ha + t0 * hb, ha + t1 * hb


@njit(cache=True, nogil=True, inline="always")
def _composite(col: np.ndarray, trans: np.ndarray, ly: int, lx: int, tr: float,
               rgba: tuple[float, float, float, float], t_min: float) -> int:
    """Front-to-back "under" of a premultiplied segment at tile pixel (ly, lx) with transmittance ``tr`` so far;
    returns 1 if the pixel just became opaque (transmittance below ``t_min``)."""
    col[ly, lx, 0] += tr * rgba[0]
    col[ly, lx, 1] += tr * rgba[1]
    col[ly, lx, 2] += tr * rgba[2]
    tr *= 1.0 - rgba[3]
    trans[ly, lx] = tr
    return 1 if tr < t_min else 0


@njit(cache=True, nogil=True, inline="always", error_model="numpy", fastmath={"contract"})
def _span(xa: int, xb: int, x0: int, ly: int, py: float, cq: np.ndarray, fr: np.ndarray, near: float,
          far_row: np.ndarray, dn_row: np.ndarray, lut: np.ndarray, lut_i: np.ndarray, lut_f: np.ndarray,
          t_min: float, col: np.ndarray, trans: np.ndarray, hq: np.ndarray, shaded: bool) -> tuple[int, int]:
    """Composite one row span of a cell whose faces are classified once (``fr[f]``: entry face) into the tile.

    Entry faces (eye outside) bound t from below; where their denominator is >= 0 the ray never enters and the pixel
    is rejected. Exit faces bound t from above; where their denominator is <= 0 the ray never leaves through that
    plane and it is ignored. With the roles fixed per cell the per-pixel branches are predictable, and the raster
    takes less CPU time than with the general per-pixel classification, for the same image
    (docs/bench/docstring-figures.md). Returns (fragments, newly opaque)."""
    sab = cq[24] + py * cq[26]
    sgb = cq[27] + py * cq[29]
    nf = 0
    opaque = 0
    for px in range(xa, xb + 1):
        lx = px - x0
        tr = trans[ly, lx]
        if tr < t_min:
            continue
        x = float(px)
        t0 = near
        t1 = far_row[px]
        for f in range(4):          # a constant trip count: unrolled by the compiler
            b = 6 * f
            d = cq[b + 3] + py * cq[b + 5] + x * cq[b + 4]
            v = (cq[b] + py * cq[b + 2] + x * cq[b + 1]) / d
            if fr[f]:
                t0 = max(t0, v if d < 0.0 else 1e300)
            else:
                t1 = min(t1, v if d > 0.0 else 1e300)
        if not t0 < t1:
            continue
        sa = sab + x * cq[25]
        sg = sgb + x * cq[28]
        hf, hb = _shade_ends(hq, x, py, t0, t1) if shaded else (1.0, 1.0)
        rgba = lookup_any(lut, lut_i, lut_f, sa + t0 * sg, sa + t1 * sg, (t1 - t0) * dn_row[px], hf, hb)
        opaque += _composite(col, trans, ly, lx, tr, rgba, t_min)
        nf += 1
    return nf, opaque


@njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def raster_tiles(box: np.ndarray, coef: np.ndarray, vxy: np.ndarray, ptr: np.ndarray, items: np.ndarray,
                 tile_order: np.ndarray, rb: np.ndarray, near: float, lut: np.ndarray, lut_i: np.ndarray,
                 lut_f: np.ndarray, width: int, height: int, tile: int, t_min: float, tol: float, far_img: np.ndarray,
                 dn_img: np.ndarray, parallel: bool, shade_coef: np.ndarray, image: np.ndarray) -> np.ndarray:
    """Composite every tile's cells front to back into ``image`` (H, W, 4); returns fragments drawn per tile.

    ``far_img`` (H, W) is the per-pixel far limit on the ray depth t (the far plane, or opaque geometry from a depth
    buffer), ``dn_img`` (H, W) the length |D| of each pixel's ray direction. A cell whose faces have a fixed role for
    every pixel (the eye, or the direction of a parallel projection, strictly off every face plane: all but
    degenerate views) goes through ``_span``; the others through the general per-pixel classification with the
    in-plane tie-break. ``shade_coef`` (k, 6): per cell the shading intensity as affine forms a + t b of the pixel
    (the layout of the scalar's coefficients), for smooth isosurfaces; an empty (0, 6) array for none."""
    shaded = shade_coef.shape[0] == coef.shape[0] and coef.shape[0] > 0
    empty6 = np.ones(6)
    tx = (width + tile - 1) // tile
    frags = np.zeros(len(tile_order), np.int64)
    for ti in prange(len(tile_order)):
        t = tile_order[ti]
        x0 = (t % tx) * tile
        y0 = (t // tx) * tile
        x1 = min(x0 + tile, width) - 1
        y1 = min(y0 + tile, height) - 1
        npx = (x1 - x0 + 1) * (y1 - y0 + 1)
        col = np.zeros((tile, tile, 3))
        trans = np.ones((tile, tile))
        fr = np.zeros(4, np.bool_)
        opaque = 0
        nf = 0
        for it in range(ptr[t + 1] - 1, ptr[t] - 1, -1):
            if opaque >= npx:
                break
            q = items[it]
            cq = coef[q]
            vq = vxy[q]
            hq = shade_coef[q] if shaded else empty6
            full = vq[0] != vq[0]
            fast = True
            for f in range(4):
                if parallel:        # the denominator n.D is constant: entry iff it is negative
                    dcon = cq[6 * f + 3]
                    fr[f] = dcon < 0.0
                    fast = fast and abs(dcon) > 1e-12 * dn_img[0, 0]
                else:               # the numerator d - n.eye is constant: entry iff the eye is outside
                    ncon = cq[6 * f]
                    fr[f] = ncon < 0.0
                    fast = fast and abs(ncon) > tol
            for py in range(max(box[q, 2], y0), min(box[q, 3], y1) + 1):
                xa = max(box[q, 0], x0)
                xb = min(box[q, 1], x1)
                if not full:
                    lo, hi = _row_span(vq, float(py))
                    if lo > hi:
                        continue
                    xa = max(xa, int(math.ceil(lo - 1e-7)))
                    xb = min(xb, int(math.floor(hi + 1e-7)))
                if fast:
                    n_add, o_add = _span(xa, xb, x0, py - y0, float(py), cq, fr, near, far_img[py], dn_img[py],
                                         lut, lut_i, lut_f, t_min, col, trans, hq, shaded)
                    nf += n_add
                    opaque += o_add
                    continue
                for px in range(xa, xb + 1):
                    ly = py - y0
                    lx = px - x0
                    tr = trans[ly, lx]
                    if tr < t_min:
                        continue
                    t0 = near
                    t1 = far_img[py, px]
                    ok = True
                    dn = dn_img[py, px]
                    eps = 1e-12 * dn
                    for f in range(4):
                        b = 6 * f
                        num = cq[b] + px * cq[b + 1] + py * cq[b + 2]
                        den = cq[b + 3] + px * cq[b + 4] + py * cq[b + 5]
                        if den > eps:
                            v = num / den
                            if v < t1:
                                t1 = v
                        elif den < -eps:
                            v = num / den
                            if v > t0:
                                t0 = v
                        elif num < -tol or (num <= tol and cq[30 + f] < 0.0):
                            ok = False
                    if not ok or t0 >= t1:
                        continue
                    sa = cq[24] + px * cq[25] + py * cq[26]
                    sb = cq[27] + px * cq[28] + py * cq[29]
                    ln = (t1 - t0) * dn
                    hf, hb = _shade_ends(hq, float(px), float(py), t0, t1) if shaded else (1.0, 1.0)
                    rgba = lookup_any(lut, lut_i, lut_f, sa + t0 * sb, sa + t1 * sb, ln, hf, hb)
                    opaque += _composite(col, trans, ly, lx, tr, rgba, t_min)
                    nf += 1
        frags[ti] = nf
        for py in range(y0, y1 + 1):
            for px in range(x0, x1 + 1):
                image[py, px, 0] = col[py - y0, px - x0, 0]
                image[py, px, 1] = col[py - y0, px - x0, 1]
                image[py, px, 2] = col[py - y0, px - x0, 2]
                image[py, px, 3] = 1.0 - trans[py - y0, px - x0]
    return frags


def ray_images(rb: np.ndarray, near: float, far: float, depth_far: np.ndarray, width: int, height: int
               ) -> tuple[np.ndarray, np.ndarray]:
    """(far_img, dn_img) for ``raster_tiles``: per pixel the far limit min(far, depth limit) and |D|."""
    px = np.arange(width, dtype=np.float64)[None, :, None]
    py = np.arange(height, dtype=np.float64)[:, None, None]
    d = rb[3][None, None, :] + px * rb[4][None, None, :] + py * rb[5][None, None, :]
    dn = np.sqrt(np.einsum("hwk,hwk->hw", d, d))
    far_img = np.full((height, width), float(far))
    if depth_far.shape == (height, width):
        np.minimum(far_img, depth_far, out=far_img)
    return far_img, np.ascontiguousarray(dn)
