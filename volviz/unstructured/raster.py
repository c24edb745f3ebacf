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
contribute nothing, so no fill-convention is needed: no pixel is drawn twice or missed.

Compositing is front to back over the reversed visibility order (equivalent to back-to-front "over",
C = C_seg + (1 - a_seg) C_behind), in screen tiles processed in parallel; a tile stops when every pixel's transmittance
is below ``t_min`` (early ray termination; error <= t_min per channel). The table lookup is trilinear.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

TILE = 32
#: per-cell coefficients: 4 faces x (num0, numx, numy, den0, denx, deny), then scalar (a0, ax, ay, b0, bx, by)
N_COEF = 30


@njit(cache=True, nogil=True, parallel=True)
def project_cells(pts: np.ndarray, tets: np.ndarray, scal: np.ndarray, cells: np.ndarray, face_n: np.ndarray,
                  face_d: np.ndarray, rb: np.ndarray, frame: np.ndarray, scales: np.ndarray, parallel: bool,
                  near: float, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel boxes (k, 4) [c0, c1, r0, r1] and coefficients (k, 30) of the listed cells (positions relative)."""
    k = len(cells)
    box = np.empty((k, 4), np.int64)
    coef = np.empty((k, N_COEF))
    for q in prange(k):
        c = cells[q]
        # --- pixel box from the projected vertices (whole screen if a vertex is at/behind the near plane)
        xmin, xmax, ymin, ymax = 1e300, -1e300, 1e300, -1e300
        full = False
        for v in range(4):
            p = pts[tets[c, v]]
            rel0 = p[0] - frame[3, 0]
            rel1 = p[1] - frame[3, 1]
            rel2 = p[2] - frame[3, 2]
            x = rel0 * frame[0, 0] + rel1 * frame[0, 1] + rel2 * frame[0, 2]
            y = rel0 * frame[1, 0] + rel1 * frame[1, 1] + rel2 * frame[1, 2]
            z = rel0 * frame[2, 0] + rel1 * frame[2, 1] + rel2 * frame[2, 2]
            if not parallel:
                if z <= near * (1.0 + 1e-9):
                    full = True
                    break
                x /= z
                y /= z
            px = (x / scales[0] + 1.0) * width * 0.5 - 0.5
            py = (1.0 - y / scales[1]) * height * 0.5 - 0.5
            xmin, xmax = min(xmin, px), max(xmax, px)
            ymin, ymax = min(ymin, py), max(ymax, py)
        if full:
            box[q, 0], box[q, 1], box[q, 2], box[q, 3] = 0, width - 1, 0, height - 1
        else:
            box[q, 0] = max(int(math.floor(xmin)) - 1, 0)
            box[q, 1] = min(int(math.ceil(xmax)) + 1, width - 1)
            box[q, 2] = max(int(math.floor(ymin)) - 1, 0)
            box[q, 3] = min(int(math.ceil(ymax)) + 1, height - 1)
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
        # --- scalar gradient g (E g = ds, Cramer) and s(x) = s0 + g.(x - p0)
        p0 = pts[tets[c, 0]]
        e = np.empty((3, 3))
        ds = np.empty(3)
        for r in range(3):
            pr = pts[tets[c, r + 1]]
            for a in range(3):
                e[r, a] = pr[a] - p0[a]
            ds[r] = scal[tets[c, r + 1]] - scal[tets[c, 0]]
        det = (e[0, 0] * (e[1, 1] * e[2, 2] - e[1, 2] * e[2, 1]) - e[0, 1] * (e[1, 0] * e[2, 2] - e[1, 2] * e[2, 0])
               + e[0, 2] * (e[1, 0] * e[2, 1] - e[1, 1] * e[2, 0]))
        g = np.zeros(3)
        if det != 0.0:
            for a in range(3):
                m = e.copy()
                for r in range(3):
                    m[r, a] = ds[r]
                g[a] = (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1])
                        - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
                        + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0])) / det
        s0 = scal[tets[c, 0]] - (g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2])
        coef[q, 24] = s0 + g[0] * rb[0, 0] + g[1] * rb[0, 1] + g[2] * rb[0, 2]
        coef[q, 25] = g[0] * rb[1, 0] + g[1] * rb[1, 1] + g[2] * rb[1, 2]
        coef[q, 26] = g[0] * rb[2, 0] + g[1] * rb[2, 1] + g[2] * rb[2, 2]
        coef[q, 27] = g[0] * rb[3, 0] + g[1] * rb[3, 1] + g[2] * rb[3, 2]
        coef[q, 28] = g[0] * rb[4, 0] + g[1] * rb[4, 1] + g[2] * rb[4, 2]
        coef[q, 29] = g[0] * rb[5, 0] + g[1] * rb[5, 1] + g[2] * rb[5, 2]
    return box, coef


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
def _lookup(table: np.ndarray, s_lo: float, inv_ds: float, inv_dl: float, sf: float, sb: float, ln: float,
            out: np.ndarray) -> None:
    n = table.shape[0]
    nl = table.shape[2]
    fi = (sf - s_lo) * inv_ds
    fj = (sb - s_lo) * inv_ds
    fk = ln * inv_dl
    fi = min(max(fi, 0.0), n - 1.0)
    fj = min(max(fj, 0.0), n - 1.0)
    fk = min(max(fk, 0.0), nl - 1.0)
    i = min(int(fi), n - 2)
    j = min(int(fj), n - 2)
    k = min(int(fk), nl - 2)
    wi = fi - i
    wj = fj - j
    wk = fk - k
    for ch in range(4):
        a = (1 - wk) * table[i, j, k, ch] + wk * table[i, j, k + 1, ch]
        b = (1 - wk) * table[i, j + 1, k, ch] + wk * table[i, j + 1, k + 1, ch]
        c = (1 - wk) * table[i + 1, j, k, ch] + wk * table[i + 1, j, k + 1, ch]
        d = (1 - wk) * table[i + 1, j + 1, k, ch] + wk * table[i + 1, j + 1, k + 1, ch]
        out[ch] = (1 - wi) * ((1 - wj) * a + wj * b) + wi * ((1 - wj) * c + wj * d)


@njit(cache=True, nogil=True, parallel=True)
def raster_tiles(box: np.ndarray, coef: np.ndarray, ptr: np.ndarray, items: np.ndarray, tile_order: np.ndarray,
                 rb: np.ndarray, near: float, far: float, table: np.ndarray, s_lo: float, ds: float, dl: float,
                 width: int, height: int, tile: int, t_min: float, image: np.ndarray) -> np.ndarray:
    """Composite every tile's cells front to back into ``image`` (H, W, 4); returns fragments drawn per tile."""
    tx = (width + tile - 1) // tile
    frags = np.zeros(len(tile_order), np.int64)
    inv_ds = 1.0 / ds
    inv_dl = 1.0 / dl
    for ti in prange(len(tile_order)):
        t = tile_order[ti]
        x0 = (t % tx) * tile
        y0 = (t // tx) * tile
        x1 = min(x0 + tile, width) - 1
        y1 = min(y0 + tile, height) - 1
        npx = (x1 - x0 + 1) * (y1 - y0 + 1)
        col = np.zeros((tile, tile, 3))
        trans = np.ones((tile, tile))
        rgba = np.empty(4)
        opaque = 0
        nf = 0
        for it in range(ptr[t + 1] - 1, ptr[t] - 1, -1):
            if opaque >= npx:
                break
            q = items[it]
            cq = coef[q]
            for py in range(max(box[q, 2], y0), min(box[q, 3], y1) + 1):
                for px in range(max(box[q, 0], x0), min(box[q, 1], x1) + 1):
                    ly = py - y0
                    lx = px - x0
                    tr = trans[ly, lx]
                    if tr < t_min:
                        continue
                    t0 = near
                    t1 = far
                    ok = True
                    for f in range(4):
                        b = 6 * f
                        num = cq[b] + px * cq[b + 1] + py * cq[b + 2]
                        den = cq[b + 3] + px * cq[b + 4] + py * cq[b + 5]
                        if den > 0.0:
                            v = num / den
                            if v < t1:
                                t1 = v
                        elif den < 0.0:
                            v = num / den
                            if v > t0:
                                t0 = v
                        elif num < 0.0:
                            ok = False
                    if not ok or t0 >= t1:
                        continue
                    sa = cq[24] + px * cq[25] + py * cq[26]
                    sb = cq[27] + px * cq[28] + py * cq[29]
                    d0 = rb[3, 0] + px * rb[4, 0] + py * rb[5, 0]
                    d1 = rb[3, 1] + px * rb[4, 1] + py * rb[5, 1]
                    d2 = rb[3, 2] + px * rb[4, 2] + py * rb[5, 2]
                    ln = (t1 - t0) * math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                    _lookup(table, s_lo, inv_ds, inv_dl, sa + t0 * sb, sa + t1 * sb, ln, rgba)
                    col[ly, lx, 0] += tr * rgba[0]
                    col[ly, lx, 1] += tr * rgba[1]
                    col[ly, lx, 2] += tr * rgba[2]
                    tr *= 1.0 - rgba[3]
                    trans[ly, lx] = tr
                    nf += 1
                    if tr < t_min:
                        opaque += 1
        frags[ti] = nf
        for py in range(y0, y1 + 1):
            for px in range(x0, x1 + 1):
                image[py, px, 0] = col[py - y0, px - x0, 0]
                image[py, px, 1] = col[py - y0, px - x0, 1]
                image[py, px, 2] = col[py - y0, px - x0, 2]
                image[py, px, 3] = 1.0 - trans[py - y0, px - x0]
    return frags

