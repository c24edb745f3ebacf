"""Integer 5/3 lifting wavelet on bricks (Guthe §2.2.1 and §2.3.1).

The reversible LeGall 5/3 wavelet (JPEG 2000's integer transform, Calderbank et al. lifting) with whole-sample
symmetric extension (mirroring, so a brick needs no samples from outside)::

    d[n] = x[2n+1] - floor((x[2n] + x[2n+2]) / 2)
    s[n] = x[2n]   + floor((d[n-1] + d[n] + 2) / 4)

is applied along x, y and z of a brick in turn (tensor-product / non-standard decomposition). The inverse undoes
the two lifting steps in reverse order, so it is bit-exact for any integer input.

Brick layout (documented alternative to Guthe's 15^3 + border textures): the volume is cut into tiles of
``TILE = 32`` samples per axis (the last tile per axis may be shorter, of any length >= 1); one level of the
transform per tile produces a lowpass brick of ``ceil(n/2)`` samples per axis -- the k^3 = 16^3 node of Guthe's
wavelet octree -- and the detail coefficients that reconstruct the node's eight 16^3 children. The lowpass bricks
of 2x2x2 neighbouring tiles form the next level's 32^3 tile, until the root fits in 16^3. Each tile is
transformed on its own, so each node's details decode independently (random access, corrupt-brick isolation,
out-of-core processing), at the cost of a slightly lower ratio than a whole-volume transform.

Per-node transform choice (lossless files only, container version 2): a tile may instead use the integer Haar /
S-transform (Said & Pearlman's reversible Haar, no overlap between neighbouring pairs)::

    d[n] = x[2n+1] - x[2n]
    s[n] = x[2n] + floor(d[n] / 2)          (= floor((x[2n] + x[2n+1]) / 2); a lone last sample passes through)

with the same [s | d] layout, so the octree, the lowpass pyramid and the scan order stay the same. An isolated
non-zero voxel touches one 2x2x2 block of S-transform coefficients (27 positions under the 5/3's 3-tap overlap), which
pays on sparse noisy data such as the embryo's background; the encoder codes each tile both ways and keeps the
smaller (``TRANSFORM_53`` / ``TRANSFORM_HAAR``, recorded per brick in the container). The 5/3 stays the default and
is the only transform of lossy files.

Kernels work on a C-ordered ``int32`` buffer ``w[i, j, k]`` (i along x) of shape (TILE, TILE, TILE) with active
extents (n0, n1, n2). After the forward transform axis ``a`` holds ``[lowpass (ceil(n/2)) | highpass (n//2)]``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

TILE = 32
HALF = TILE // 2
TRANSFORM_53 = 0
TRANSFORM_HAAR = 1


@njit(cache=True, nogil=True)
def _fwd_line(x, n, tmp):
    """One forward 5/3 lifting step on ``x[0:n]`` in place -> [s | d] (symmetric extension)."""
    if n < 2:
        return
    nl = (n + 1) // 2
    nh = n // 2
    for i in range(nh):
        a = x[2 * i]
        b = x[2 * i + 2] if 2 * i + 2 < n else a
        tmp[nl + i] = x[2 * i + 1] - ((a + b) >> 1)
    for i in range(nl):
        dl = tmp[nl + i - 1] if i > 0 else tmp[nl]
        dr = tmp[nl + i] if i < nh else tmp[nl + nh - 1]
        tmp[i] = x[2 * i] + ((dl + dr + 2) >> 2)
    for i in range(n):
        x[i] = tmp[i]


@njit(cache=True, nogil=True)
def _inv_line(x, n, tmp):
    """Inverse of :func:`_fwd_line`: ``x[0:n]`` holds [s | d], becomes the signal."""
    if n < 2:
        return
    nl = (n + 1) // 2
    nh = n // 2
    for i in range(nl):
        dl = x[nl + i - 1] if i > 0 else x[nl]
        dr = x[nl + i] if i < nh else x[nl + nh - 1]
        tmp[2 * i] = x[i] - ((dl + dr + 2) >> 2)
    for i in range(nh):
        a = tmp[2 * i]
        b = tmp[2 * i + 2] if 2 * i + 2 < n else a
        tmp[2 * i + 1] = x[nl + i] + ((a + b) >> 1)
    for i in range(n):
        x[i] = tmp[i]


@njit(cache=True, nogil=True)
def _copy_box(src, dst, m0, m1, m2):
    """``dst[:m0, :m1, :m2] = src[:m0, :m1, :m2]`` (3D views)."""
    for i in range(m0):
        for j in range(m1):
            for k in range(m2):
                dst[i, j, k] = src[i, j, k]


@njit(cache=True, nogil=True)
def _planes(v, m0, m1, m2, tmp, inverse):
    """Lift along axis 0 of the 3D view ``v`` (active box m0 x m1 x m2) one whole plane at a time, so the inner
    loops run over contiguous memory (strided line gathers hit cache-set conflicts at the 4 KiB plane stride)."""
    if m0 < 2:
        return
    nl = (m0 + 1) // 2
    nh = m0 // 2
    if not inverse:
        for i in range(nh):
            a = 2 * i
            b = 2 * i + 2 if 2 * i + 2 < m0 else a
            for j in range(m1):
                for k in range(m2):
                    tmp[nl + i, j, k] = v[2 * i + 1, j, k] - ((v[a, j, k] + v[b, j, k]) >> 1)
        for i in range(nl):
            dl = nl + i - 1 if i > 0 else nl
            dr = nl + i if i < nh else nl + nh - 1
            for j in range(m1):
                for k in range(m2):
                    tmp[i, j, k] = v[2 * i, j, k] + ((tmp[dl, j, k] + tmp[dr, j, k] + 2) >> 2)
    else:
        for i in range(nl):
            dl = nl + i - 1 if i > 0 else nl
            dr = nl + i if i < nh else nl + nh - 1
            for j in range(m1):
                for k in range(m2):
                    tmp[2 * i, j, k] = v[i, j, k] - ((v[dl, j, k] + v[dr, j, k] + 2) >> 2)
        for i in range(nh):
            a = 2 * i
            b = 2 * i + 2 if 2 * i + 2 < m0 else a
            for j in range(m1):
                for k in range(m2):
                    tmp[2 * i + 1, j, k] = v[nl + i, j, k] + ((tmp[a, j, k] + tmp[b, j, k]) >> 1)
    _copy_box(tmp, v, m0, m1, m2)


@njit(cache=True, nogil=True)
def _lines(w, n0, n1, n2, inverse):
    """Lift every contiguous line along axis 2."""
    if n2 < 2:
        return
    tmp = np.empty(TILE, np.int32)
    for i in range(n0):
        for j in range(n1):
            if inverse:
                _inv_line(w[i, j], n2, tmp)
            else:
                _fwd_line(w[i, j], n2, tmp)


@njit(cache=True, nogil=True)
def _inv_lines(w, n0, n1, n2):
    """Inverse lifting of every line along axis 2 (same arithmetic as :func:`_inv_line`, with the mirrored border
    samples peeled out of the loops; about 1.6x faster, the z pass dominates the inverse transform)."""
    if n2 < 2:
        return
    nl = (n2 + 1) // 2
    nh = n2 // 2
    t = np.empty(TILE, np.int32)
    for i in range(n0):
        for j in range(n1):
            x = w[i, j]
            t[0] = x[0] - ((x[nl] + x[nl] + 2) >> 2)
            for m in range(1, nh):
                t[2 * m] = x[m] - ((x[nl + m - 1] + x[nl + m] + 2) >> 2)
            if nl > nh:
                t[2 * nh] = x[nh] - ((x[nl + nh - 1] + x[nl + nh - 1] + 2) >> 2)
                for m in range(nh):
                    t[2 * m + 1] = x[nl + m] + ((t[2 * m] + t[2 * m + 2]) >> 1)
            else:
                for m in range(nh - 1):
                    t[2 * m + 1] = x[nl + m] + ((t[2 * m] + t[2 * m + 2]) >> 1)
                t[n2 - 1] = x[n2 - 1] + ((t[n2 - 2] + t[n2 - 2]) >> 1)
            for m in range(n2):
                x[m] = t[m]


@njit(cache=True, nogil=True)
def forward_tile(w, n0, n1, n2):
    """One 3D level of the forward transform on the active box of the tile buffer ``w`` (in place): z, y, x."""
    tmp = np.empty((TILE, TILE, TILE), np.int32)
    _lines(w, n0, n1, n2, False)
    _planes(w.transpose(1, 0, 2), n1, n0, n2, tmp, False)
    _planes(w, n0, n1, n2, tmp, False)


@njit(cache=True, nogil=True)
def _inv_planes_to(src, dst, m0, m1, m2):
    """Inverse lifting along axis 0 from ``src`` ([s | d] halves) into ``dst`` (interleaved signal); the same
    arithmetic as the inverse branch of :func:`_planes` without the copy back (ping-pong buffers)."""
    if m0 < 2:
        for j in range(m1):
            for k in range(m2):
                dst[0, j, k] = src[0, j, k]
        return
    nl = (m0 + 1) // 2
    nh = m0 // 2
    for i in range(nl):
        dl = nl + i - 1 if i > 0 else nl
        dr = nl + i if i < nh else nl + nh - 1
        for j in range(m1):
            s_row = src[i, j]
            l_row = src[dl, j]
            r_row = src[dr, j]
            o_row = dst[2 * i, j]
            for k in range(m2):
                o_row[k] = s_row[k] - ((l_row[k] + r_row[k] + 2) >> 2)
    for i in range(nh):
        a = 2 * i
        b = 2 * i + 2 if 2 * i + 2 < m0 else a
        for j in range(m1):
            d_row = src[nl + i, j]
            a_row = dst[a, j]
            b_row = dst[b, j]
            o_row = dst[2 * i + 1, j]
            for k in range(m2):
                o_row[k] = d_row[k] + ((a_row[k] + b_row[k]) >> 1)


@njit(cache=True, nogil=True)
def inverse_tile_with(w, tmp, n0, n1, n2):
    """Inverse of :func:`forward_tile` (bit-exact) with a caller-provided scratch tile ``tmp``: x (w -> tmp),
    y (tmp -> w, on transposed views), then z in place. Two full-tile copies fewer than :func:`_planes`."""
    _inv_planes_to(w, tmp, n0, n1, n2)
    _inv_planes_to(tmp.transpose(1, 0, 2), w.transpose(1, 0, 2), n1, n0, n2)
    _inv_lines(w, n0, n1, n2)


@njit(cache=True, nogil=True)
def inverse_tile(w, n0, n1, n2):
    """Inverse of :func:`forward_tile` (bit-exact): x, y, z."""
    tmp = np.empty((TILE, TILE, TILE), np.int32)
    inverse_tile_with(w, tmp, n0, n1, n2)


@njit(cache=True, nogil=True)
def _haar_planes(v, m0, m1, m2, tmp, inverse):
    """S-transform along axis 0 of the 3D view ``v`` (active box m0 x m1 x m2), whole planes at a time."""
    if m0 < 2:
        return
    nl = (m0 + 1) // 2
    nh = m0 // 2
    if not inverse:
        for i in range(nh):
            for j in range(m1):
                a_row = v[2 * i, j]
                b_row = v[2 * i + 1, j]
                s_row = tmp[i, j]
                d_row = tmp[nl + i, j]
                for k in range(m2):
                    d = b_row[k] - a_row[k]
                    d_row[k] = d
                    s_row[k] = a_row[k] + (d >> 1)
        if nl > nh:
            for j in range(m1):
                for k in range(m2):
                    tmp[nh, j, k] = v[m0 - 1, j, k]
    else:
        for i in range(nh):
            for j in range(m1):
                s_row = v[i, j]
                d_row = v[nl + i, j]
                a_row = tmp[2 * i, j]
                b_row = tmp[2 * i + 1, j]
                for k in range(m2):
                    d = d_row[k]
                    a = s_row[k] - (d >> 1)
                    a_row[k] = a
                    b_row[k] = a + d
        if nl > nh:
            for j in range(m1):
                for k in range(m2):
                    tmp[m0 - 1, j, k] = v[nh, j, k]
    _copy_box(tmp, v, m0, m1, m2)


@njit(cache=True, nogil=True)
def _haar_lines(w, n0, n1, n2, inverse):
    """S-transform of every contiguous line along axis 2."""
    if n2 < 2:
        return
    nl = (n2 + 1) // 2
    nh = n2 // 2
    t = np.empty(TILE, np.int32)
    for i in range(n0):
        for j in range(n1):
            x = w[i, j]
            if not inverse:
                for m in range(nh):
                    d = x[2 * m + 1] - x[2 * m]
                    t[nl + m] = d
                    t[m] = x[2 * m] + (d >> 1)
                if nl > nh:
                    t[nh] = x[n2 - 1]
            else:
                for m in range(nh):
                    d = x[nl + m]
                    a = x[m] - (d >> 1)
                    t[2 * m] = a
                    t[2 * m + 1] = a + d
                if nl > nh:
                    t[n2 - 1] = x[nh]
            for m in range(n2):
                x[m] = t[m]


@njit(cache=True, nogil=True)
def haar_forward_tile(w, n0, n1, n2):
    """One 3D level of the integer Haar / S-transform on the active box of ``w`` (in place): z, y, x; the same
    [lowpass | highpass] layout per axis as :func:`forward_tile`."""
    tmp = np.empty((TILE, TILE, TILE), np.int32)
    _haar_lines(w, n0, n1, n2, False)
    _haar_planes(w.transpose(1, 0, 2), n1, n0, n2, tmp, False)
    _haar_planes(w, n0, n1, n2, tmp, False)


@njit(cache=True, nogil=True)
def haar_inverse_tile_with(w, tmp, n0, n1, n2):
    """Inverse of :func:`haar_forward_tile` (bit-exact): x, y, z, with a caller-provided scratch tile."""
    _haar_planes(w, n0, n1, n2, tmp, True)
    _haar_planes(w.transpose(1, 0, 2), n1, n0, n2, tmp, True)
    _haar_lines(w, n0, n1, n2, True)


@njit(cache=True, nogil=True)
def forward_tile_t(w, n0, n1, n2, transform):
    """:func:`forward_tile` (``TRANSFORM_53``) or :func:`haar_forward_tile` (``TRANSFORM_HAAR``)."""
    if transform == TRANSFORM_HAAR:
        haar_forward_tile(w, n0, n1, n2)
    else:
        forward_tile(w, n0, n1, n2)


@njit(cache=True, nogil=True)
def inverse_tile_t(w, tmp, n0, n1, n2, transform):
    """Inverse of :func:`forward_tile_t` with a scratch tile ``tmp``."""
    if transform == TRANSFORM_HAAR:
        haar_inverse_tile_with(w, tmp, n0, n1, n2)
    else:
        inverse_tile_with(w, tmp, n0, n1, n2)


def n_tiles(n: int) -> int:
    """Tiles along an axis of ``n`` samples."""
    return (n + TILE - 1) // TILE


def level_shapes(shape: tuple[int, int, int], max_levels: int | None = None) -> list[tuple[int, int, int]]:
    """Shapes of the lowpass pyramid: level 0 is the volume, the last entry is the root (all axes <= 16)."""
    shapes = [tuple(int(s) for s in shape)]
    while max(shapes[-1]) > HALF and (max_levels is None or len(shapes) - 1 < max_levels):
        shapes.append(tuple((s + 1) // 2 for s in shapes[-1]))
    return shapes  # type: ignore[return-value]


def _synthesis_norms(levels: int) -> tuple[np.ndarray, np.ndarray]:
    """Squared L2 norms of the 1D 5/3 synthesis basis functions: (lowpass[j], highpass[j]) for j = 0..levels."""
    g0 = np.array([0.5, 1.0, 0.5])
    g1 = np.array([-0.125, -0.25, 0.75, -0.25, -0.125])
    low = np.ones(levels + 1)
    high = np.zeros(levels + 1)
    for j in range(1, levels + 1):
        for branch, out in ((g0, low), (g1, high)):
            f = branch
            for _ in range(j - 1):  # pass through j-1 coarser-to-finer lowpass synthesis stages
                up = np.zeros(2 * len(f) - 1)
                up[::2] = f
                f = np.convolve(up, g0)
            out[j] = float(np.sum(f * f))
    return low, high


def subband_weights(levels: int) -> np.ndarray:
    """Energy weight of a unit error in each subband: ``weights[l, b]`` for level l = 1..levels, subband b = 0..7.

    Subband ``b`` has bit ``a`` set when axis ``a`` is highpass; b = 0 is the lowpass (used for the root at the top
    level). An error e in a coefficient of (l, b) adds about ``weights[l, b] * e**2`` to the squared error of the
    volume, so quantising with steps ``delta / sqrt(weights)`` spreads the error evenly (MSE-optimal uniform
    allocation for the non-orthogonal 5/3 basis; the tile borders make it approximate).
    """
    low, high = _synthesis_norms(levels)
    w = np.ones((levels + 1, 8))
    for level in range(1, levels + 1):
        for b in range(8):
            prod = 1.0
            for axis in range(3):
                prod *= high[level] if (b >> axis) & 1 else low[level]
            w[level, b] = prod
    return w
