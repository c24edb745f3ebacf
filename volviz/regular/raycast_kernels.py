"""Numba kernels of the one-pass block ray caster (``volviz.regular.raycast``): block lookup through a coarse index
grid, per-block trilinear sampling, separable pre-integration (Roettger Ch. 9) and the float64 reference.

Coordinates: everything runs in level-0 *index space* (sample (i, j, k) of the finest level sits at (i, j, k)); a ray
``O + t D`` (world) becomes ``oi + t di`` with ``oi = (O - origin) / spacing``, ``di = D / spacing``, and a parameter
interval ``dt`` is ``dt |D|`` world units long. Rows are dealt out in ``nch`` interleaved chunks (chunk c takes rows
c, c + nch, ...), so that each thread's contiguous run of ``prange`` iterations spans the whole image.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from volviz.optics.integrate import _segment

_BIG = 1e300


@numba.njit(cache=True, nogil=True, inline="always")
def _slab(o, d, hi):
    """(t_enter, t_exit) of the ray o + t d through the box [0, hi] (t_enter > t_exit: missed)."""
    t0 = -_BIG
    t1 = _BIG
    for a in range(3):
        if d[a] > 0.0:
            ta = -o[a] / d[a]
            tb = (hi[a] - o[a]) / d[a]
        elif d[a] < 0.0:
            ta = (hi[a] - o[a]) / d[a]
            tb = -o[a] / d[a]
        else:
            if o[a] < 0.0 or o[a] > hi[a]:
                return _BIG, -_BIG
            continue
        if ta > t0:
            t0 = ta
        if tb < t1:
            t1 = tb
    return t0, t1


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _box_exit(o, d, lo0, lo1, lo2, hi0, hi1, hi2):
    """Exit parameter of the ray from the box [lo, hi] (the ray is assumed to be inside)."""
    t1 = _BIG
    lo = (lo0, lo1, lo2)
    hi = (hi0, hi1, hi2)
    for a in range(3):
        if d[a] > 0.0:
            tb = (hi[a] - o[a]) / d[a]
        elif d[a] < 0.0:
            tb = (lo[a] - o[a]) / d[a]
        else:
            continue
        if tb < t1:
            t1 = tb
    return t1


@numba.njit(cache=True, nogil=True, inline="always")
def _axis(x, n):
    """(i0, i1, w) of the linear interpolation at fractional index x, clamped to [0, n - 1]."""
    if n < 2 or x <= 0.0:
        return 0, min(1, n - 1), 0.0
    if x >= n - 1:
        return n - 2, n - 1, 1.0
    i = int(x)
    return i, i + 1, x - i


@numba.njit(cache=True, nogil=True, inline="always")
def _sample_block(data, off, nx, ny, nz, x, y, z):
    """Trilinear sample of the C-ordered brick data[off:off + nx ny nz] at local index (x, y, z) (clamped)."""
    i0, i1, wx = _axis(x, nx)
    j0, j1, wy = _axis(y, ny)
    k0, k1, wz = _axis(z, nz)
    b00 = off + (i0 * ny + j0) * nz
    b01 = off + (i0 * ny + j1) * nz
    b10 = off + (i1 * ny + j0) * nz
    b11 = off + (i1 * ny + j1) * nz
    c00 = data[b00 + k0] + wz * (data[b00 + k1] - data[b00 + k0])
    c01 = data[b01 + k0] + wz * (data[b01 + k1] - data[b01 + k0])
    c10 = data[b10 + k0] + wz * (data[b10 + k1] - data[b10 + k0])
    c11 = data[b11 + k0] + wz * (data[b11 + k1] - data[b11 + k0])
    c0 = c00 + wy * (c01 - c00)
    c1 = c10 + wy * (c11 - c10)
    return c0 + wx * (c1 - c0)


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _separable(tab, s_lo, inv_ds, u, degree, kmax, sf, sb, length, seg):
    """Separable pre-integration (Roettger §9.1): α = 1 − exp(−l ρ̂(s_f, s_b)) (exact but for the bilinear ρ̂),
    color = α · clamp(Σ C̃_i u^i, 0, κ_max), u = min(l / l_max, 1) (given, with 1 / ds). Writes seg[0:4]; NaN
    scalars give 0."""
    n = tab.shape[0]
    if sf != sf or sb != sb:
        seg[0] = 0.0
        seg[1] = 0.0
        seg[2] = 0.0
        seg[3] = 0.0
        return
    i0, i1, wi = _axis((sf - s_lo) * inv_ds, n)
    j0, j1, wj = _axis((sb - s_lo) * inv_ds, n)
    w00 = (1.0 - wi) * (1.0 - wj)
    w01 = (1.0 - wi) * wj
    w10 = wi * (1.0 - wj)
    w11 = wi * wj
    rho = w00 * tab[i0, j0, 0] + w01 * tab[i0, j1, 0] + w10 * tab[i1, j0, 0] + w11 * tab[i1, j1, 0]
    alpha = -math.expm1(-length * rho) if rho > 0.0 else 0.0
    seg[3] = alpha
    if alpha <= 0.0:
        seg[0] = 0.0
        seg[1] = 0.0
        seg[2] = 0.0
        return
    for ch in range(3):
        acc = 0.0
        for d in range(degree, -1, -1):
            c = 1 + d * 3 + ch
            acc = acc * u + (w00 * tab[i0, j0, c] + w01 * tab[i0, j1, c] + w10 * tab[i1, j0, c]
                             + w11 * tab[i1, j1, c])
        if acc < 0.0:
            acc = 0.0
        elif acc > kmax[ch]:
            acc = kmax[ch]
        seg[ch] = acc * alpha


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _ray_interval(basis, row, col, spacing, hi, t_near, depth, planes, o, d):
    """Fill o, d (index space) for pixel (row, col); returns (t0, t1, |D|) of the ray inside the volume box [0, hi],
    beyond t_near, before the pixel's depth limit and on the kept side of every clipping plane (n . x + w >= 0)."""
    dl2 = 0.0
    for a in range(3):
        ow = basis[0, a] + col * basis[1, a] + row * basis[2, a]
        dw = basis[3, a] + col * basis[4, a] + row * basis[5, a]
        dl2 += dw * dw
        o[a] = ow / spacing[a]
        d[a] = dw / spacing[a]
    t0, t1 = _slab(o, d, hi)
    t0 = max(t0, t_near)
    if depth.shape[0] > 0:
        t1 = min(t1, depth[row, col])
    for p in range(planes.shape[0]):        # planes in index space: n . x + w >= 0 is kept
        a = planes[p, 3]
        b = 0.0
        for ax in range(3):
            a += planes[p, ax] * o[ax]
            b += planes[p, ax] * d[ax]
        if b == 0.0:
            if a < 0.0:
                return 1.0, 0.0, 1.0
        elif b > 0.0:
            t0 = max(t0, -a / b)
        else:
            t1 = min(t1, -a / b)
    return t0, t1, math.sqrt(dl2)


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def cast_blocks(basis, size, spacing, hi, t_near, depth, planes, data, offset, dims, blo, bhi, scale, active,
                grid, cell, soff, sdims, sact, sub, tab, s_lo, ds, l_max, degree, kmax, z_lo, z_hi, step, t_stop,
                nch, out):
    """Front-to-back ray casting over packed blocks (see ``volviz.regular.raycast``); out (H, W, 4) float32, zeroed
    by the caller (pixels whose ray misses the volume are not written). ρ = 0 for scalars < z_lo and > z_hi:
    segments with both ends there are transparent without a table lookup."""
    w = size[0]
    h = size[1]
    gx, gy, gz = grid.shape
    min_sp = min(spacing[0], min(spacing[1], spacing[2]))
    inv_ds = 1.0 / ds
    for chunk in numba.prange(nch):
        o = np.empty(3)
        d = np.empty(3)
        seg = np.empty(4)
        for row in range(chunk, h, nch):
            for col in range(w):
                t0, t1, dlen = _ray_interval(basis, row, col, spacing, hi, t_near, depth, planes, o, d)
                if not t1 > t0:
                    continue
                dmax = max(abs(d[0]), max(abs(d[1]), abs(d[2])))
                eps = 1e-4 / dmax                          # 1e-4 voxel along the ray
                trans = 1.0
                cr = 0.0
                cg = 0.0
                cb = 0.0
                t = t0
                while t < t1 and trans > t_stop:
                    te = t + eps
                    ci = min(max(int((o[0] + te * d[0]) / cell), 0), gx - 1)
                    cj = min(max(int((o[1] + te * d[1]) / cell), 0), gy - 1)
                    ck = min(max(int((o[2] + te * d[2]) / cell), 0), gz - 1)
                    b = grid[ci, cj, ck]
                    if b < 0:                              # no block here: leap over the grid cell
                        tn = _box_exit(o, d, ci * cell, cj * cell, ck * cell, (ci + 1) * cell, (cj + 1) * cell,
                                       (ck + 1) * cell)
                        t = max(tn, te)
                        continue
                    tb = min(_box_exit(o, d, blo[b, 0], blo[b, 1], blo[b, 2], bhi[b, 0], bhi[b, 1], bhi[b, 2]), t1)
                    if not active[b]:                      # transparent under this TF: leap over the block
                        t = max(tb, te)
                        continue
                    if tb <= t:
                        t = te
                        continue
                    sc = scale[b]
                    dt = step * sc * min_sp / dlen
                    off = offset[b]
                    nx, ny, nz = dims[b, 0], dims[b, 1], dims[b, 2]
                    ux, uy, uz = sdims[b, 0], sdims[b, 1], sdims[b, 2]
                    edge = sub * sc
                    inv_sc = 1.0 / sc
                    t_carry = -math.inf
                    sf = 0.0
                    while t < tb and trans > t_stop:       # the block's sub-cells along the ray
                        te = t + eps
                        si = min(max(int((o[0] + te * d[0] - blo[b, 0]) / edge), 0), ux - 1)
                        sj = min(max(int((o[1] + te * d[1] - blo[b, 1]) / edge), 0), uy - 1)
                        sk = min(max(int((o[2] + te * d[2] - blo[b, 2]) / edge), 0), uz - 1)
                        lx = blo[b, 0] + si * edge
                        ly = blo[b, 1] + sj * edge
                        lz = blo[b, 2] + sk * edge
                        hx = bhi[b, 0] if si == ux - 1 else min(lx + edge, bhi[b, 0])
                        hy = bhi[b, 1] if sj == uy - 1 else min(ly + edge, bhi[b, 1])
                        hz = bhi[b, 2] if sk == uz - 1 else min(lz + edge, bhi[b, 2])
                        ts = min(_box_exit(o, d, lx, ly, lz, hx, hy, hz), tb)
                        if ts <= t:
                            ts = te
                        if sact[soff[b] + (si * uy + sj) * uz + sk] == 0:   # transparent sub-cell: leap
                            t = ts
                            continue
                        n = max(1, int(math.ceil((ts - t) / dt - 1e-6)))
                        hh = (ts - t) / n
                        length = hh * dlen
                        u = min(length / l_max, 1.0)
                        # local (brick index) position at t and its increment per step
                        px = (o[0] + t * d[0] - blo[b, 0]) * inv_sc
                        py = (o[1] + t * d[1] - blo[b, 1]) * inv_sc
                        pz = (o[2] + t * d[2] - blo[b, 2]) * inv_sc
                        qx = hh * d[0] * inv_sc
                        qy = hh * d[1] * inv_sc
                        qz = hh * d[2] * inv_sc
                        if t != t_carry:
                            sf = _sample_block(data, off, nx, ny, nz, px, py, pz)
                        for k in range(1, n + 1):
                            sb = _sample_block(data, off, nx, ny, nz, px + k * qx, py + k * qy, pz + k * qz)
                            if (sf < z_lo and sb < z_lo) or (sf > z_hi and sb > z_hi):
                                sf = sb
                                continue
                            _separable(tab, s_lo, inv_ds, u, degree, kmax, sf, sb, length, seg)
                            if seg[3] > 0.0:
                                cr += trans * seg[0]
                                cg += trans * seg[1]
                                cb += trans * seg[2]
                                trans *= 1.0 - seg[3]
                                if trans <= t_stop:
                                    break
                            sf = sb
                        t = ts
                        t_carry = ts
                    t = tb
                out[row, col, 0] = cr
                out[row, col, 1] = cg
                out[row, col, 2] = cb
                out[row, col, 3] = 1.0 - trans


@numba.njit(cache=True, nogil=True, parallel=True)
def cast_reference(basis, size, spacing, hi, t_near, depth, planes, vol, vdims, sc, col, ext, msc, mcol, mext, step,
                   nch, out):
    """Float64 reference: the full-resolution volume ``vol`` (C-ordered, flattened, ``vdims`` samples) sampled
    trilinearly at uniform steps of ``step`` voxels (of the smallest spacing) along each ray, every segment integrated
    exactly (Roettger Eq. 8.1, the kernel of ``integrate_segment``); no early termination. out (H, W, 4) float64,
    zeroed by the caller."""
    w = size[0]
    h = size[1]
    nx, ny, nz = vdims[0], vdims[1], vdims[2]
    min_sp = min(spacing[0], min(spacing[1], spacing[2]))
    for chunk in numba.prange(nch):
        o = np.empty(3)
        d = np.empty(3)
        seg = np.empty(4)
        acc = np.empty(3)
        for row in range(chunk, h, nch):
            for col_ in range(w):
                t0, t1, dlen = _ray_interval(basis, row, col_, spacing, hi, t_near, depth, planes, o, d)
                if not t1 > t0:
                    continue
                n = max(1, int(math.ceil((t1 - t0) * dlen / (step * min_sp))))
                hh = (t1 - t0) / n
                length = hh * dlen
                trans = 1.0
                for c in range(3):
                    acc[c] = 0.0
                sf = _sample_block(vol, 0, nx, ny, nz, o[0] + t0 * d[0], o[1] + t0 * d[1], o[2] + t0 * d[2])
                for k in range(1, n + 1):
                    tk = t0 + k * hh
                    sb = _sample_block(vol, 0, nx, ny, nz, o[0] + tk * d[0], o[1] + tk * d[1], o[2] + tk * d[2])
                    if sb < sf:
                        _segment(msc, mcol, mext, -sf, -sb, length, seg)
                    else:
                        _segment(sc, col, ext, sf, sb, length, seg)
                    for c in range(3):
                        acc[c] += trans * seg[c]
                    trans *= 1.0 - seg[3]
                    sf = sb
                    if trans < 1e-15:
                        break
                for c in range(3):
                    out[row, col_, c] = acc[c]
                out[row, col_, 3] = 1.0 - trans


@numba.njit(cache=True, nogil=True)
def sub_ranges(data, offset, dims, soff, sdims, sub, out_min, out_max):
    """Per block and sub-cell (i, j, k): min and max of the finite samples [sub i, sub (i + 1)] x ... (clipped to
    the brick), i.e. of every sample that trilinear interpolation inside the sub-cell uses; +inf / -inf if none."""
    for b in range(offset.shape[0]):
        nx, ny, nz = dims[b, 0], dims[b, 1], dims[b, 2]
        ux, uy, uz = sdims[b, 0], sdims[b, 1], sdims[b, 2]
        for si in range(ux):
            for sj in range(uy):
                for sk in range(uz):
                    lo = np.inf
                    hi = -np.inf
                    for i in range(si * sub, min((si + 1) * sub, nx - 1) + 1):
                        for j in range(sj * sub, min((sj + 1) * sub, ny - 1) + 1):
                            base = offset[b] + (i * ny + j) * nz
                            for k in range(sk * sub, min((sk + 1) * sub, nz - 1) + 1):
                                v = data[base + k]
                                if v == v:
                                    lo = min(lo, v)
                                    hi = max(hi, v)
                    m = soff[b] + (si * uy + sj) * uz + sk
                    out_min[m] = lo
                    out_max[m] = hi
