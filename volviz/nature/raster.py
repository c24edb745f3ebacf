"""CPU rasterisation of the (opaque) terrain: a float64 z-buffer and a lit, textured color image.

The volumes of a natural scene (fog prisms, clouds) are composited over this depth: a pixel's fog and cloud segments
end where its ray meets the terrain. Conventions are those of ``volviz.model.camera.Camera``: pixel centres at
integer (col, row), row 0 at the top, depth = distance along the direction of projection (the ray parameter t).

Triangles are clipped against the near plane in camera space (Sutherland–Hodgman, one plane) and rasterised with
perspective-correct interpolation (1/z and attribute/z linear in screen space). Shading: a baked color map
(texture times a static ambient + diffuse light map from the full-resolution normals, Roettger §4.4) sampled with
trilinear mip-mapping, so lighting does not change with the LOD (only the geometry does) and nothing aliases.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, prange

from volviz.nature.heightfield import grid_from_image, resample_bilinear


def view_params(camera: Any, size: tuple[int, int]) -> np.ndarray:
    """(16,) float64: eye(3), right(3), up(3), forward(3), hx, hy, near, far (perspective only)."""
    if camera.parallel:
        raise ValueError("natural scenes need a perspective camera")
    r, u, f = camera.frame()
    w, h = size
    hy = math.tan(math.radians(camera.view_angle) / 2.0)
    hx = hy * w / h
    near, far = camera.clipping_range
    return np.concatenate([np.asarray(camera.position, float), r, u, f, [hx, hy, near, far]])


@njit(cache=True, nogil=True)
def to_camera(vp: np.ndarray, p: np.ndarray, out: np.ndarray) -> None:
    """World points (n, 3) -> camera coordinates (x right, y up, z along the view) in ``out``."""
    for i in range(p.shape[0]):
        dx, dy, dz = p[i, 0] - vp[0], p[i, 1] - vp[1], p[i, 2] - vp[2]
        out[i, 0] = dx * vp[3] + dy * vp[4] + dz * vp[5]
        out[i, 1] = dx * vp[6] + dy * vp[7] + dz * vp[8]
        out[i, 2] = dx * vp[9] + dy * vp[10] + dz * vp[11]


PRISM_EDGES = np.array([[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3], [0, 3], [1, 4], [2, 5]], dtype=np.int64)
CUBE_EDGES = np.array([[q, q | b] for q in range(8) for b in (4, 2, 1) if not q & b], dtype=np.int64)


@njit(cache=True, nogil=True)
def clipped_screen_box(cam: np.ndarray, edges: np.ndarray, vp: np.ndarray, w: int, h: int, out: np.ndarray) -> bool:
    """Pixel box out = [x0, x1, y0, y1] (clamped to the image) of a convex cell from its vertices in camera space and
    its edges, clipped at the near plane: the vertices in front plus the edges' near-plane crossings. False if no part
    of the cell is in front of the near plane or the box misses the image."""
    near = vp[14]
    x0, x1, y0, y1 = 1e300, -1e300, 1e300, -1e300
    anyv = False
    for v in range(cam.shape[0]):
        if cam[v, 2] >= near:
            sx = (cam[v, 0] / cam[v, 2] / vp[12] + 1.0) * w * 0.5 - 0.5
            sy = (1.0 - cam[v, 1] / cam[v, 2] / vp[13]) * h * 0.5 - 0.5
            x0, x1, y0, y1 = min(x0, sx), max(x1, sx), min(y0, sy), max(y1, sy)
            anyv = True
    for e in range(edges.shape[0]):
        a, b = edges[e, 0], edges[e, 1]
        za, zb = cam[a, 2], cam[b, 2]
        if (za >= near) != (zb >= near):
            f = (near - za) / (zb - za)
            cx = cam[a, 0] + f * (cam[b, 0] - cam[a, 0])
            cy = cam[a, 1] + f * (cam[b, 1] - cam[a, 1])
            sx = (cx / near / vp[12] + 1.0) * w * 0.5 - 0.5
            sy = (1.0 - cy / near / vp[13]) * h * 0.5 - 0.5
            x0, x1, y0, y1 = min(x0, sx), max(x1, sx), min(y0, sy), max(y1, sy)
            anyv = True
    if not anyv:
        return False
    out[0] = max(int(math.floor(x0)), 0)
    out[1] = min(int(math.ceil(x1)), w - 1)
    out[2] = max(int(math.floor(y0)), 0)
    out[3] = min(int(math.ceil(y1)), h - 1)
    return out[0] <= out[1] and out[2] <= out[3]


@njit(cache=True, nogil=True, inline="always")
def _screen(vp, w, h, x, y, z):
    return (x / z / vp[12] + 1.0) * w * 0.5 - 0.5, (1.0 - y / z / vp[13]) * h * 0.5 - 0.5


@njit(cache=True, nogil=True)
def _bilinear(img: np.ndarray, r: float, c: float, ch: int) -> float:
    rows, cols = img.shape[0], img.shape[1]
    r = min(max(r, 0.0), rows - 1.0)
    c = min(max(c, 0.0), cols - 1.0)
    r0 = min(int(r), rows - 2) if rows > 1 else 0
    c0 = min(int(c), cols - 2) if cols > 1 else 0
    fr, fc = r - r0, c - c0
    r1, c1 = min(r0 + 1, rows - 1), min(c0 + 1, cols - 1)
    return ((1 - fr) * ((1 - fc) * img[r0, c0, ch] + fc * img[r0, c1, ch])
            + fr * ((1 - fc) * img[r1, c0, ch] + fc * img[r1, c1, ch]))


@njit(cache=True, nogil=True)
def _raster_poly(px, py, iz, au, av, nvert, w, h, row0, row1, depth, uvbuf):
    """Rasterise a convex screen polygon (fan) into rows [row0, row1): z-test on depth, store (u, v) of the winner."""
    for t in range(1, nvert - 1):
        i0, i1, i2 = 0, t, t + 1
        x0, y0, x1, y1, x2, y2 = px[i0], py[i0], px[i1], py[i1], px[i2], py[i2]
        area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if area == 0.0 or not math.isfinite(area):
            continue
        xmin = max(int(math.ceil(min(x0, x1, x2))), 0)
        xmax = min(int(math.floor(max(x0, x1, x2))), w - 1)
        ymin = max(int(math.ceil(min(y0, y1, y2))), row0)
        ymax = min(int(math.floor(max(y0, y1, y2))), row1 - 1)
        inv = 1.0 / area
        for yy in range(ymin, ymax + 1):
            for xx in range(xmin, xmax + 1):
                b0 = ((x1 - xx) * (y2 - yy) - (x2 - xx) * (y1 - yy)) * inv
                b1 = ((x2 - xx) * (y0 - yy) - (x0 - xx) * (y2 - yy)) * inv
                b2 = 1.0 - b0 - b1
                if b0 < 0.0 or b1 < 0.0 or b2 < 0.0:
                    continue
                q = b0 * iz[i0] + b1 * iz[i1] + b2 * iz[i2]
                if q <= 0.0:
                    continue
                z = 1.0 / q
                if z < depth[yy, xx]:
                    depth[yy, xx] = z
                    uvbuf[yy, xx, 0] = (b0 * au[i0] + b1 * au[i1] + b2 * au[i2]) * z
                    uvbuf[yy, xx, 1] = (b0 * av[i0] + b1 * av[i1] + b2 * av[i2]) * z


@njit(cache=True, nogil=True)
def _raster_band(vp, cam, sy, tris, tc, w, h, row0, row1, depth, uvbuf):
    near = vp[14]
    cx = np.empty(8)
    cy = np.empty(8)
    cz = np.empty(8)
    cu = np.empty(8)
    cv = np.empty(8)
    px = np.empty(8)
    py = np.empty(8)
    iz = np.empty(8)
    au = np.empty(8)
    av = np.empty(8)
    for t in range(tris.shape[0]):
        i0, i1, i2 = tris[t, 0], tris[t, 1], tris[t, 2]
        if cam[i0, 2] >= near and cam[i1, 2] >= near and cam[i2, 2] >= near:
            # fast reject by the precomputed screen rows when no clipping is needed
            if max(sy[i0], sy[i1], sy[i2]) < row0 - 1 or min(sy[i0], sy[i1], sy[i2]) > row1:
                continue
        # near-plane clipping of the triangle (camera space)
        nv = 0
        for e in range(3):
            a = tris[t, e]
            b = tris[t, (e + 1) % 3]
            za, zb = cam[a, 2], cam[b, 2]
            if za >= near:
                cx[nv], cy[nv], cz[nv], cu[nv], cv[nv] = cam[a, 0], cam[a, 1], za, tc[a, 0], tc[a, 1]
                nv += 1
            if (za >= near) != (zb >= near):
                s = (near - za) / (zb - za)
                cx[nv] = cam[a, 0] + s * (cam[b, 0] - cam[a, 0])
                cy[nv] = cam[a, 1] + s * (cam[b, 1] - cam[a, 1])
                cz[nv] = near
                cu[nv] = tc[a, 0] + s * (tc[b, 0] - tc[a, 0])
                cv[nv] = tc[a, 1] + s * (tc[b, 1] - tc[a, 1])
                nv += 1
        if nv < 3:
            continue
        ymin = 1e300
        ymax = -1e300
        for k in range(nv):
            sx_, sy_ = _screen(vp, w, h, cx[k], cy[k], cz[k])
            px[k], py[k] = sx_, sy_
            iz[k] = 1.0 / cz[k]
            au[k] = cu[k] * iz[k]
            av[k] = cv[k] * iz[k]
            ymin = min(ymin, sy_)
            ymax = max(ymax, sy_)
        if ymax < row0 - 1 or ymin > row1:
            continue
        _raster_poly(px, py, iz, au, av, nv, w, h, row0, row1, depth, uvbuf)


@njit(cache=True, nogil=True, parallel=True)
def _raster(vp, cam, tris, tc, w, h, bands, depth, uvbuf):
    nb = bands.shape[0] - 1
    sy = np.empty(cam.shape[0])
    for i in prange(cam.shape[0]):
        sy[i] = (1.0 - cam[i, 1] / cam[i, 2] / vp[13]) * h * 0.5 - 0.5 if cam[i, 2] > 0 else 0.0
    for b in prange(nb):
        _raster_band(vp, cam, sy, tris, tc, w, h, bands[b], bands[b + 1], depth, uvbuf)


def mip_pyramid(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A (2^n + 1)-sized (N, N, 3) color map and its [1 2 1]/4 decimations down to 2 x 2, packed for Numba:
    (flat float32 data, (levels, 2) int64 [offset, size])."""
    levels = [np.asarray(image, dtype=np.float32)]
    while levels[-1].shape[0] > 2:
        a = levels[-1]
        n = (a.shape[0] - 1) // 2 + 1
        pad = np.pad(a, ((1, 1), (1, 1), (0, 0)), mode="edge")
        rows = 0.25 * pad[0:-2:2] + 0.5 * pad[1:-1:2] + 0.25 * pad[2::2]
        levels.append(np.ascontiguousarray(0.25 * rows[:, 0:-2:2] + 0.5 * rows[:, 1:-1:2]
                                           + 0.25 * rows[:, 2::2])[:n, :n])
    meta = np.zeros((len(levels), 2), dtype=np.int64)
    off = 0
    for k, lev in enumerate(levels):
        meta[k] = (off, lev.shape[0])
        off += lev.size
    return np.concatenate([lev.ravel() for lev in levels]).astype(np.float32), meta


@njit(cache=True, nogil=True)
def _mip_sample(flat, meta, level, gi, gj, out):
    """Bilinear sample of level ``level`` at fine-grid coordinates (gi, gj), accumulated into out[0:3]."""
    off, n = meta[level, 0], meta[level, 1]
    scale = (n - 1) / (meta[0, 1] - 1)
    x = min(max(gi * scale, 0.0), n - 1.0)
    y = min(max(gj * scale, 0.0), n - 1.0)
    i0 = min(int(x), n - 2) if n > 1 else 0
    j0 = min(int(y), n - 2) if n > 1 else 0
    fx, fy = x - i0, y - j0
    for c in range(3):
        a = flat[off + (i0 * n + j0) * 3 + c]
        b = flat[off + ((i0 + 1) * n + j0) * 3 + c]
        e = flat[off + (i0 * n + j0 + 1) * 3 + c]
        d = flat[off + ((i0 + 1) * n + j0 + 1) * 3 + c]
        out[c] = (1 - fx) * ((1 - fy) * a + fy * e) + fx * ((1 - fy) * b + fy * d)


@njit(cache=True, nogil=True)
def _footprint(depth, uvbuf, y, x, scale):
    """Texels per pixel at (y, x): the smaller of forward/backward uv differences per axis (robust at silhouettes)."""
    h, w = depth.shape
    y = np.int64(y)
    x = np.int64(x)
    best = 0.0
    for axis in range(2):
        m = 1e300
        for s in (-1, 1):
            yy = y + s if axis == 0 else y
            xx = x if axis == 0 else x + s
            if 0 <= yy < h and 0 <= xx < w and math.isfinite(depth[yy, xx]):
                du = (uvbuf[yy, xx, 0] - uvbuf[y, x, 0]) * scale
                dv = (uvbuf[yy, xx, 1] - uvbuf[y, x, 1]) * scale
                m = min(m, math.sqrt(du * du + dv * dv))
        if m < 1e300:
            best = max(best, m)
    return best


@njit(cache=True, nogil=True, parallel=True)
def _shade(depth, uvbuf, flat, meta, out):
    h, w = depth.shape
    nlev = meta.shape[0]
    scale = meta[0, 1] - 1.0
    for y in prange(h):
        c0 = np.empty(3)
        c1 = np.empty(3)
        for x in range(w):
            if not math.isfinite(depth[y, x]):
                continue
            gi, gj = uvbuf[y, x, 0] * scale, uvbuf[y, x, 1] * scale
            lam = math.log2(max(_footprint(depth, uvbuf, y, x, scale), 1.0))
            lam = min(lam, nlev - 1.0)
            l0 = int(lam)
            f = lam - l0
            _mip_sample(flat, meta, l0, gi, gj, c0)
            if f > 0.0 and l0 + 1 < nlev:
                _mip_sample(flat, meta, l0 + 1, gi, gj, c1)
                for c in range(3):
                    out[y, x, c] = (1 - f) * c0[c] + f * c1[c]
            else:
                for c in range(3):
                    out[y, x, c] = c0[c]


def bake_color_map(normals: np.ndarray, texture: np.ndarray | None = None, light=(0.4, 0.3, 0.85),
                    ambient: float = 0.45, diffuse: float = 0.65, base_color=(0.55, 0.5, 0.42)) -> np.ndarray:
    """The terrain's static light map times its color texture on the height-field grid, (N, N, 3) float32
    (Roettger §4.4: static ambient + diffuse light map).
    ``normals[i, j]`` x-major; the texture image has row 0 north."""
    n = normals.shape[0]
    L = np.asarray(light, dtype=np.float64)
    L = L / np.linalg.norm(L)
    shade = ambient + diffuse * np.clip(normals @ L, 0.0, None)
    if texture is None:
        col = np.broadcast_to(np.asarray(base_color, dtype=np.float64), (n, n, 3))
    else:
        tex = np.asarray(texture, dtype=np.float64)
        col = np.stack([resample_bilinear(grid_from_image(tex[..., c]), (n, n)) for c in range(3)], axis=-1)
    return np.ascontiguousarray(col * shade[..., None], dtype=np.float32)


def row_bands(h: int, parts: int = 4) -> np.ndarray:
    return np.linspace(0, h, min(parts, h) + 1).round().astype(np.int64)


@njit(cache=True, nogil=True, inline="always")
def dealt_band(ii: int, nb: int, threads: int) -> int:
    """The band for iteration ``ii`` of ``prange(dealt_count(nb, threads))``: prange gives each thread a contiguous
    run of iterations, and this deals the bands out so that each run takes every ``threads``-th band (the whole
    image, not one strip of it: clouds and fog are not spread evenly over the rows). -1 for padding iterations."""
    nt = max(1, min(threads, nb))
    per = (nb + nt - 1) // nt
    bi = (ii % per) * nt + ii // per
    return bi if bi < nb else -1


@njit(cache=True, nogil=True, inline="always")
def dealt_count(nb: int, threads: int) -> int:
    nt = max(1, min(threads, nb))
    return nt * ((nb + nt - 1) // nt)


def render_terrain(points: np.ndarray, triangles: np.ndarray, tcoords: np.ndarray, camera: Any, size: tuple[int, int],
                   color_pyramid: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Depth (H, W) float64 (inf where no terrain) and color (H, W, 3) float32 of a terrain mesh.

    ``tcoords`` (u, v) in [0, 1] address the baked color map (``bake_color_map``, packed by ``mip_pyramid``), sampled
    trilinearly with the mip level from each pixel's texel footprint, so a minified texture does not alias and the
    image is a smooth function of the geometry (a geometric LOD error shows as a proportional image error).
    """
    w, h = (int(v) for v in size)
    vp = view_params(camera, (w, h))
    cam = np.empty((len(points), 3))
    to_camera(vp, np.ascontiguousarray(points, dtype=np.float64), cam)
    depth = np.full((h, w), np.inf)
    uv = np.zeros((h, w, 2))
    _raster(vp, cam, np.ascontiguousarray(triangles, dtype=np.int64), np.ascontiguousarray(tcoords, dtype=np.float64),
            w, h, row_bands(h), depth, uv)
    far = camera.clipping_range[1]
    depth[depth > far] = np.inf
    rgb = np.zeros((h, w, 3), dtype=np.float32)
    _shade(depth, uv, color_pyramid[0], color_pyramid[1], rgb)
    return depth, rgb


@njit(cache=True, nogil=True, parallel=True)
def _sky(vp, w, h, tex, zenith, horizon, has_tex, mask, out):
    for y in prange(h):
        for x in range(w):
            if not mask[y, x]:
                continue
            sx = (2.0 * (x + 0.5) / w - 1.0) * vp[12]
            sy = (1.0 - 2.0 * (y + 0.5) / h) * vp[13]
            dx = vp[9] + sx * vp[3] + sy * vp[6]
            dy = vp[10] + sx * vp[4] + sy * vp[7]
            dz = vp[11] + sx * vp[5] + sy * vp[8]
            n = math.sqrt(dx * dx + dy * dy + dz * dz)
            elev = math.asin(max(min(dz / n, 1.0), -1.0))
            t = max(elev, 0.0) / (0.5 * math.pi)  # 0 at the horizon, 1 at the zenith
            if has_tex:
                az = math.atan2(dy, dx)
                u = (az / (2.0 * math.pi)) % 1.0
                rows, cols = tex.shape[0], tex.shape[1]
                for c in range(3):
                    out[y, x, c] = _bilinear(tex, (1.0 - t) * (rows - 1), u * (cols - 1), c)
            else:
                for c in range(3):
                    out[y, x, c] = horizon[c] + (zenith[c] - horizon[c]) * math.sqrt(t)


def render_sky(camera: Any, size: tuple[int, int], texture: np.ndarray | None = None,
               zenith=(0.32, 0.5, 0.85), horizon=(0.78, 0.85, 0.95), mask: np.ndarray | None = None) -> np.ndarray:
    """Sky color per pixel (H, W, 3) float32: the sky dome at infinity (Roettger §5.1) — a polar texture (u =
    azimuth / 2 pi, top row = zenith, bottom row = horizon) or a zenith/horizon gradient. Below the horizon the
    horizon color continues. ``mask`` (H, W) bool: only those pixels are computed (the others stay 0), e.g. where
    no terrain covers the sky."""
    w, h = (int(v) for v in size)
    vp = view_params(camera, (w, h))
    out = np.zeros((h, w, 3), dtype=np.float32)
    tex = np.zeros((1, 1, 3), dtype=np.float32) if texture is None else np.ascontiguousarray(texture, dtype=np.float32)
    m = np.ones((h, w), dtype=np.bool_) if mask is None else np.ascontiguousarray(mask, dtype=np.bool_)
    _sky(vp, w, h, tex, np.asarray(zenith, float), np.asarray(horizon, float), texture is not None, m, out)
    return out
