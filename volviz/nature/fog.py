"""Ground fog and cloud layers: prisms on the terrain triangles rendered with PCP (Roettger Ch. 10, §10.3–10.4).

A **layer** stacks a vertical prism on every triangle of the terrain C-LOD mesh: bottom and top heights per vertex
(ground fog: terrain -> terrain + fog-map thickness; a cloud layer: two height fields, Fig. 10.6 bottom). Both are
morphed with the terrain (``TerrainLOD`` layers), so the fog is geomorphed too and flying through it does not pop.

**PCP, per-pixel exact equivalent.** PCP's three passes (§10.3) leave, per pixel and per convex cell, the emission
½ (κ_f + κ_b)(d_b − d_f): the average of the front and back emission times the length of the ray inside the cell
(the trapezoid rule, exact for emission linear along the ray), summed over cells without sorting. Here every prism is
intersected with each pixel ray of its screen box analytically (5 half-spaces: 3 vertical sides, bottom, top), in
float64, with the ray clipped to [near, min(far, terrain depth)]:

- the near-plane **cap** of §10.4 is implicit: a prism cut by the near plane starts at t = near, with the emission
  interpolated there (what the cap pass supplies);
- the terrain occludes fog behind it (the depth is the CPU terrain z-buffer);
- prisms whose six vertex emissions are all zero are skipped (§10.3, "zero-emission cells were discarded").

The emission field in a prism is Σ λ_i [(1 − u) e_bottom,i + u e_top,i] (λ barycentric in the base triangle, u the
height fraction between bottom and top), i.e. the interpolation PCP's front and back faces perform.

Modes (per layer, ``render_layer``):

- ``"emissive"``: RGB = color · Σ ½ (e_f + e_b) l (additive, α = 0): the thesis's emission-only model;
- ``"attenuated"``: the same integral used as optical depth τ: α = 1 − e^{−τ}, RGB = color · α. For a constant
  color this *is* the exact emission–absorption integral whatever the density distribution, since
  ∫ κ ρ e^{−τ(t)} dt = κ (1 − e^{−τ}) for constant κ — order independent, no sorting;
- ``"mip"`` (§10.4 MIP variant): the maximum of the vertex scalar over the ray's prism entry/exit points (the maximum
  of a linear cell lies on its faces), with scalar 0 at the prism bottom and the layer thickness at the top;
  RGB = color · min(gain · max, 1), α = min(gain · max, 1).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
from numba import njit, prange

from volviz.nature.raster import (PRISM_EDGES, clipped_screen_box, dealt_band, dealt_count, row_bands,
                                  view_params)


@dataclass
class FogLayer:
    """Optical settings of one prism layer (ground fog or cloud layer)."""

    color: tuple[float, float, float] = (0.75, 0.75, 1.0)
    density: float = 0.05          # emission / optical density per unit length at e = 1
    mode: str = "attenuated"       # "emissive" | "attenuated" | "mip"
    mip_gain: float = 0.05         # MIP: intensity per unit of layer thickness

    def __post_init__(self) -> None:
        if self.mode not in ("emissive", "attenuated", "mip"):
            raise ValueError(f"fog mode must be emissive, attenuated or mip, got {self.mode!r}")
        if not (self.density >= 0 and math.isfinite(self.density)):
            raise ValueError(f"fog density must be finite and >= 0, got {self.density}")


@njit(cache=True, nogil=True, parallel=True)
def _prism_setup(pts, bot, top, eb, et, tris, vp, w, h, planes, boxes, keep):
    """In parallel over chunks of prisms (``_prism_setup_range``)."""
    m = tris.shape[0]
    chunks = 16
    for ci in prange(chunks):
        _prism_setup_range(pts, bot, top, eb, et, tris, vp, w, h, planes, boxes, keep, ci * m // chunks,
                           (ci + 1) * m // chunks)


@njit(cache=True, nogil=True)
def _prism_setup_range(pts, bot, top, eb, et, tris, vp, w, h, planes, boxes, keep, p0, p1):
    """Per prism: 5 inward planes (a, b, c, d) and the clipped screen box [x0, x1, y0, y1]; keep[p] = 0 to skip."""
    cam = np.empty((6, 3))
    box = np.empty(4, dtype=np.int64)
    for p in range(p0, p1):
        i0, i1, i2 = tris[p, 0], tris[p, 1], tris[p, 2]
        keep[p] = 0
        if (eb[i0] <= 0 and eb[i1] <= 0 and eb[i2] <= 0 and et[i0] <= 0 and et[i1] <= 0 and et[i2] <= 0):
            continue
        if top[i0] <= bot[i0] and top[i1] <= bot[i1] and top[i2] <= bot[i2]:
            continue
        idx = (i0, i1, i2)
        # vertical sides, inward normal towards the third vertex
        for e in range(3):
            a = idx[e]
            b = idx[(e + 1) % 3]
            c = idx[(e + 2) % 3]
            nx = -(pts[b, 1] - pts[a, 1])
            ny = pts[b, 0] - pts[a, 0]
            if nx * (pts[c, 0] - pts[a, 0]) + ny * (pts[c, 1] - pts[a, 1]) < 0:
                nx, ny = -nx, -ny
            planes[p, e, 0] = nx
            planes[p, e, 1] = ny
            planes[p, e, 2] = 0.0
            planes[p, e, 3] = -(nx * pts[a, 0] + ny * pts[a, 1])
        for k in range(2):
            z = bot if k == 0 else top
            ux, uy, uz = pts[i1, 0] - pts[i0, 0], pts[i1, 1] - pts[i0, 1], z[i1] - z[i0]
            vx, vy, vz = pts[i2, 0] - pts[i0, 0], pts[i2, 1] - pts[i0, 1], z[i2] - z[i0]
            nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
            if nz < 0:
                nx, ny, nz = -nx, -ny, -nz
            if k == 1:
                nx, ny, nz = -nx, -ny, -nz
            planes[p, 3 + k, 0] = nx
            planes[p, 3 + k, 1] = ny
            planes[p, 3 + k, 2] = nz
            planes[p, 3 + k, 3] = -(nx * pts[i0, 0] + ny * pts[i0, 1] + nz * z[i0])
        # screen box of the prism clipped to the near plane: vertices in front + edge/near-plane intersections
        for v in range(6):
            q = idx[v % 3]
            z = bot[q] if v < 3 else top[q]
            dx, dy, dz = pts[q, 0] - vp[0], pts[q, 1] - vp[1], z - vp[2]
            cam[v, 0] = dx * vp[3] + dy * vp[4] + dz * vp[5]
            cam[v, 1] = dx * vp[6] + dy * vp[7] + dz * vp[8]
            cam[v, 2] = dx * vp[9] + dy * vp[10] + dz * vp[11]
        if not clipped_screen_box(cam, PRISM_EDGES, vp, w, h, box):
            continue
        for k in range(4):
            boxes[p, k] = box[k]
        keep[p] = 1


@njit(cache=True, nogil=True)
def _field(pts, bot, top, eb, et, i0, i1, i2, x, y, z):
    """Emission at (x, y, z) inside the prism: barycentric over the base, linear between bottom and top."""
    x0, y0 = pts[i0, 0], pts[i0, 1]
    ux, uy = pts[i1, 0] - x0, pts[i1, 1] - y0
    vx, vy = pts[i2, 0] - x0, pts[i2, 1] - y0
    det = ux * vy - uy * vx
    px, py = x - x0, y - y0
    l1 = (px * vy - py * vx) / det
    l2 = (ux * py - uy * px) / det
    l0 = 1.0 - l1 - l2
    zb = l0 * bot[i0] + l1 * bot[i1] + l2 * bot[i2]
    zt = l0 * top[i0] + l1 * top[i1] + l2 * top[i2]
    dz = zt - zb
    u = 0.5 if dz <= 1e-12 else min(max((z - zb) / dz, 0.0), 1.0)
    return (l0 * ((1 - u) * eb[i0] + u * et[i0]) + l1 * ((1 - u) * eb[i1] + u * et[i1])
            + l2 * ((1 - u) * eb[i2] + u * et[i2]))


@njit(cache=True, nogil=True)
def _pcp_band(pts, bot, top, eb, et, tris, planes, boxes, keep, rb, depth, near, row0, row1, emis, mip):
    o = np.empty(3)
    d = np.empty(3)
    ca = np.empty((5, 3))  # plane . origin = ca0 + col ca1 + row ca2 (the ray table is linear in col and row)
    cb = np.empty((5, 3))  # plane . direction, likewise
    for p in range(tris.shape[0]):
        if keep[p] == 0:
            continue
        y_lo = max(boxes[p, 2], row0)
        y_hi = min(boxes[p, 3], row1 - 1)
        if y_lo > y_hi:
            continue
        i0, i1, i2 = tris[p, 0], tris[p, 1], tris[p, 2]
        for k in range(5):
            for j in range(3):
                ca[k, j] = (planes[p, k, 0] * rb[j, 0] + planes[p, k, 1] * rb[j, 1] + planes[p, k, 2] * rb[j, 2]
                            + (planes[p, k, 3] if j == 0 else 0.0))
                cb[k, j] = (planes[p, k, 0] * rb[3 + j, 0] + planes[p, k, 1] * rb[3 + j, 1]
                            + planes[p, k, 2] * rb[3 + j, 2])
        for row in range(y_lo, y_hi + 1):
            for col in range(boxes[p, 0], boxes[p, 1] + 1):
                t0 = near
                t1 = depth[row, col]
                ok = True
                for k in range(5):
                    pa = ca[k, 0] + col * ca[k, 1] + row * ca[k, 2]
                    pb = cb[k, 0] + col * cb[k, 1] + row * cb[k, 2]
                    if pb > 0.0:
                        t0 = max(t0, -pa / pb)
                    elif pb < 0.0:
                        t1 = min(t1, -pa / pb)
                    elif pa < 0.0:
                        ok = False
                        break
                if not ok or t1 <= t0:
                    continue
                for a in range(3):
                    o[a] = rb[0, a] + col * rb[1, a] + row * rb[2, a]
                    d[a] = rb[3, a] + col * rb[4, a] + row * rb[5, a]
                ef = _field(pts, bot, top, eb, et, i0, i1, i2, o[0] + t0 * d[0], o[1] + t0 * d[1], o[2] + t0 * d[2])
                eback = _field(pts, bot, top, eb, et, i0, i1, i2, o[0] + t1 * d[0], o[1] + t1 * d[1],
                               o[2] + t1 * d[2])
                dn = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
                emis[row, col] += 0.5 * (ef + eback) * (t1 - t0) * dn
                m = max(ef, eback)
                if m > mip[row, col]:
                    mip[row, col] = m


@njit(cache=True, nogil=True, parallel=True)
def _pcp(pts, bot, top, eb, et, tris, planes, boxes, keep, rb, depth, near, bands, emis, mip, threads):
    nb = bands.shape[0] - 1
    for ii in prange(dealt_count(nb, threads)):
        b = dealt_band(ii, nb, threads)
        if b >= 0:
            _pcp_band(pts, bot, top, eb, et, tris, planes, boxes, keep, rb, depth, near, bands[b], bands[b + 1], emis,
                      mip)


def pcp_integrals(points: np.ndarray, bottom: np.ndarray, top: np.ndarray, triangles: np.ndarray,
                  emission_bottom: np.ndarray, emission_top: np.ndarray, camera: Any, size: tuple[int, int],
                  depth: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """Per pixel: Σ ½ (e_f + e_b)(d_b − d_f) over all prisms (world lengths) and the MIP maximum of e at the prism
    entry/exit points; the third value is the number of prisms drawn (after zero-emission and screen culling)."""
    w, h = (int(v) for v in size)
    vp = view_params(camera, (w, h))
    pts = np.ascontiguousarray(points, dtype=np.float64)
    tris = np.ascontiguousarray(triangles, dtype=np.int64)
    bot = np.ascontiguousarray(bottom, dtype=np.float64)
    topv = np.ascontiguousarray(top, dtype=np.float64)
    eb = np.ascontiguousarray(emission_bottom, dtype=np.float64)
    et = np.ascontiguousarray(emission_top, dtype=np.float64)
    m = len(tris)
    planes = np.zeros((m, 5, 4))
    boxes = np.zeros((m, 4), dtype=np.int64)
    keep = np.zeros(m, dtype=np.int8)
    _prism_setup(pts, bot, topv, eb, et, tris, vp, w, h, planes, boxes, keep)
    far = camera.clipping_range[1]
    dep = np.full((h, w), far) if depth is None else np.minimum(np.asarray(depth, dtype=np.float64), far)
    rb = camera.rays((w, h)).as_array()
    emis = np.zeros((h, w))
    mip = np.zeros((h, w))
    _pcp(pts, bot, topv, eb, et, tris, planes, boxes, keep, rb, dep, float(vp[14]), row_bands(h, 16), emis, mip,
         numba.get_num_threads())
    return emis, mip, int(keep.sum())


def layer_emission(bottom: np.ndarray, top: np.ndarray, layer: FogLayer,
                   emission: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-vertex (e_bottom, e_top) of a layer: ``emission`` or 1 where the layer has thickness; the MIP mode uses 0
    at the bottom and the thickness at the top (§10.4)."""
    thick = np.asarray(top, dtype=np.float64) - np.asarray(bottom, dtype=np.float64)
    if layer.mode == "mip":
        return np.zeros_like(thick), np.maximum(thick, 0.0)
    if emission is None:
        present = (thick > 0).astype(np.float64)
        return present, present
    return emission


def render_layer(points: np.ndarray, bottom: np.ndarray, top: np.ndarray, triangles: np.ndarray, layer: FogLayer,
                 camera: Any, size: tuple[int, int], depth: np.ndarray | None = None,
                 emission: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, int]:
    """Premultiplied RGBA (H, W, 4) float64 of one prism layer and the number of prisms drawn.

    ``emission`` = (e_bottom, e_top) per vertex (default 1 where the layer has thickness, 0 elsewhere); the MIP mode
    uses 0 at the bottom and the thickness at the top (§10.4).
    """
    eb, et = layer_emission(bottom, top, layer, emission)
    emis, mip, drawn = pcp_integrals(points, bottom, top, triangles, eb, et, camera, size, depth)
    col = np.asarray(layer.color, dtype=np.float64)
    out = np.zeros(emis.shape + (4,))
    if layer.mode == "emissive":
        out[..., :3] = emis[..., None] * layer.density * col
    elif layer.mode == "attenuated":
        a = -np.expm1(-layer.density * emis)
        out[..., :3] = a[..., None] * col
        out[..., 3] = a
    else:
        a = np.minimum(layer.mip_gain * mip, 1.0)
        out[..., :3] = a[..., None] * col
        out[..., 3] = a
    return out, drawn


# --------------------------------------------------------------------------------------------------- reference
@njit(cache=True, nogil=True)
def _bucket_build(pts, tris, x0, y0, cell, nbx, nby, counts, start, items):
    for pass_ in range(2):
        for t in range(tris.shape[0]):
            xa = min(pts[tris[t, 0], 0], pts[tris[t, 1], 0], pts[tris[t, 2], 0])
            xb = max(pts[tris[t, 0], 0], pts[tris[t, 1], 0], pts[tris[t, 2], 0])
            ya = min(pts[tris[t, 0], 1], pts[tris[t, 1], 1], pts[tris[t, 2], 1])
            yb = max(pts[tris[t, 0], 1], pts[tris[t, 1], 1], pts[tris[t, 2], 1])
            for bx in range(max(int((xa - x0) / cell), 0), min(int((xb - x0) / cell), nbx - 1) + 1):
                for by in range(max(int((ya - y0) / cell), 0), min(int((yb - y0) / cell), nby - 1) + 1):
                    if pass_ == 0:
                        counts[bx * nby + by] += 1
                    else:
                        items[start[bx * nby + by] + counts[bx * nby + by]] = t
                        counts[bx * nby + by] += 1
        if pass_ == 0:
            acc = 0
            for i in range(counts.shape[0]):
                start[i] = acc
                acc += counts[i]
                counts[i] = 0


@njit(cache=True, nogil=True)
def _locate(pts, tris, x0, y0, cell, nbx, nby, counts, start, items, x, y):
    bx, by = int((x - x0) / cell), int((y - y0) / cell)
    if bx < 0 or by < 0 or bx >= nbx or by >= nby:
        return -1, 0.0, 0.0, 0.0
    b = bx * nby + by
    for k in range(start[b], start[b] + counts[b]):
        t = items[k]
        i0, i1, i2 = tris[t, 0], tris[t, 1], tris[t, 2]
        ux, uy = pts[i1, 0] - pts[i0, 0], pts[i1, 1] - pts[i0, 1]
        vx, vy = pts[i2, 0] - pts[i0, 0], pts[i2, 1] - pts[i0, 1]
        det = ux * vy - uy * vx
        px, py = x - pts[i0, 0], y - pts[i0, 1]
        l1 = (px * vy - py * vx) / det
        l2 = (ux * py - uy * px) / det
        l0 = 1.0 - l1 - l2
        if l0 >= -1e-12 and l1 >= -1e-12 and l2 >= -1e-12:
            return t, l0, l1, l2
    return -1, 0.0, 0.0, 0.0


@njit(cache=True, nogil=True, parallel=True)
def _march(pts, terrain_z, bot, top, eb, et, tris, x0, y0, cell, nbx, nby, counts, start, items, rb, near, far,
           steps, emis, mip):
    h, w = emis.shape
    for row in prange(h):
        o = np.empty(3)
        d = np.empty(3)
        for col in range(w):
            for a in range(3):
                o[a] = rb[0, a] + col * rb[1, a] + row * rb[2, a]
                d[a] = rb[3, a] + col * rb[4, a] + row * rb[5, a]
            dn = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            dt = (far - near) / steps
            acc = 0.0
            best = 0.0
            for s in range(steps):
                t = near + (s + 0.5) * dt
                x, y, z = o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]
                tri, l0, l1, l2 = _locate(pts, tris, x0, y0, cell, nbx, nby, counts, start, items, x, y)
                if tri < 0:
                    continue
                i0, i1, i2 = tris[tri, 0], tris[tri, 1], tris[tri, 2]
                zg = l0 * terrain_z[i0] + l1 * terrain_z[i1] + l2 * terrain_z[i2]
                if z < zg:
                    break  # the ray hit the terrain
                zb = l0 * bot[i0] + l1 * bot[i1] + l2 * bot[i2]
                zt = l0 * top[i0] + l1 * top[i1] + l2 * top[i2]
                if zb <= z <= zt:
                    e = _field(pts, bot, top, eb, et, i0, i1, i2, x, y, z)
                    acc += e * dt * dn
                    best = max(best, e)
            emis[row, col] = acc
            mip[row, col] = best


def reference_integrals(points: np.ndarray, terrain_z: np.ndarray, bottom: np.ndarray, top: np.ndarray,
                        triangles: np.ndarray, emission_bottom: np.ndarray, emission_top: np.ndarray, camera: Any,
                        size: tuple[int, int], steps: int = 4000) -> tuple[np.ndarray, np.ndarray]:
    """The reference emissive integral by dense ray marching (midpoint rule, ``steps`` samples from near to far):
    every sample is located in the terrain triangulation, stops the ray below the terrain surface and adds the
    prism's emission where it lies between bottom and top. Independent of the PCP kernel (no prism clipping, no
    z-buffer); its error is O(step) at each layer boundary. Slow; for tests on small meshes and images."""
    w, h = (int(v) for v in size)
    pts = np.ascontiguousarray(points, dtype=np.float64)
    tris = np.ascontiguousarray(triangles, dtype=np.int64)
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    cell = float(max(hi - lo)) / 64.0 + 1e-9
    nbx, nby = int((hi[0] - lo[0]) / cell) + 1, int((hi[1] - lo[1]) / cell) + 1
    counts = np.zeros(nbx * nby, dtype=np.int64)
    start = np.zeros(nbx * nby, dtype=np.int64)
    total = 0
    for t in tris:  # upper bound of the bucket entries
        xs, ys = pts[t, 0], pts[t, 1]
        total += (int((xs.max() - lo[0]) / cell) - int((xs.min() - lo[0]) / cell) + 1) * \
                 (int((ys.max() - lo[1]) / cell) - int((ys.min() - lo[1]) / cell) + 1)
    items = np.zeros(total, dtype=np.int64)
    _bucket_build(pts, tris, lo[0], lo[1], cell, nbx, nby, counts, start, items)
    rb = camera.rays((w, h)).as_array()
    near, far = camera.clipping_range
    emis = np.zeros((h, w))
    mip = np.zeros((h, w))
    _march(pts, np.ascontiguousarray(terrain_z, dtype=np.float64), np.ascontiguousarray(bottom, dtype=np.float64),
           np.ascontiguousarray(top, dtype=np.float64), np.ascontiguousarray(emission_bottom, dtype=np.float64),
           np.ascontiguousarray(emission_top, dtype=np.float64), tris, lo[0], lo[1], cell, nbx, nby, counts, start,
           items, rb, float(near), float(far), int(steps), emis, mip)
    return emis, mip
