"""Fused per-level kernels: tile wavelet transform + quantisation + entropy coding, parallel over tiles
(Guthe §2.2.1-2.2.2, §2.3.1).

One *level* step maps an int32 array ``a`` (n0, n1, n2) to its lowpass ``low`` (ceil(n/2) per axis) plus one coded
node per 32^3 tile. Tiles are numbered x fastest: ``t = t0 + c0 * (t1 + c1 * t2)``. In lossless levels each tile
is coded with the 5/3 and with the integer S-transform and keeps the smaller (``tfs[t]``, stored per brick).

``steps[0] > 0`` flags a lossless level: the decoder's lowpass equals the encoder's, so the arithmetic coder may use
it as context. Quantisation (lossy modes): detail subband ``b`` uses step ``steps[b]``; a step <= 1 means no
quantisation
(lossless integers). Coefficient c -> q = sign(c) * floor(|c| / step + ROUND) (a dead-zone quantiser),
reconstruction c' = sign(q) * round((|q| + BIAS) * step). ROUND = 0.40, BIAS = 0 gave the best PSNR on embryo at
1 bit/voxel with integer steps of the pairs tried (docs/bench/docstring-figures.md).
The kernels are plain ``nogil`` Numba functions over a strided subset of tiles (``first``, ``first + stride``, ...);
:func:`run_tiles` runs them on a small thread pool. (A ``prange`` version compiled several times slower for no
speed gain.)
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable

import numpy as np
from numba import njit

from .entropy import (CODER_RANS, decode_arith, decode_haar_arith, decode_rans, encode_arith, encode_haar_arith,
                      encode_rans)
from .wavelet import (HALF, TILE, TRANSFORM_53, TRANSFORM_HAAR, forward_tile, forward_tile_t, haar_forward_tile,
                      inverse_tile, inverse_tile_t)

ROUND = 0.40
BIAS = 0.0


@njit(cache=True, nogil=True)
def _tile_box(t, c0, c1, shape):
    t0 = t % c0
    t1 = (t // c0) % c1
    t2 = t // (c0 * c1)
    s0 = t0 * TILE
    s1 = t1 * TILE
    s2 = t2 * TILE
    return t0, t1, t2, s0, s1, s2, min(TILE, shape[0] - s0), min(TILE, shape[1] - s1), min(TILE, shape[2] - s2)


@njit(cache=True, nogil=True)
def _requant(w, n0, n1, n2, steps, inverse):
    """Quantise (``inverse`` False) or reconstruct (True) the detail subbands of a tile in place, one subband box
    at a time (no per-sample subband test; zeros skipped)."""
    if steps[1:].max() <= 1.0:  # lossless: nothing to do
        return
    l0 = (n0 + 1) // 2
    l1 = (n1 + 1) // 2
    l2 = (n2 + 1) // 2
    for b in range(1, 8):
        st = steps[b]
        if st <= 1.0:
            continue
        i0, i1 = (l0, n0) if b & 1 else (0, l0)
        j0, j1 = (l1, n1) if b & 2 else (0, l1)
        k0, k1 = (l2, n2) if b & 4 else (0, l2)
        ist = np.int32(st)
        if inverse and BIAS == 0.0 and ist == st:  # integer step: reconstruction is c * step (vectorised)
            for i in range(i0, i1):
                for j in range(j0, j1):
                    row = w[i, j, k0:k1]
                    for k in range(k1 - k0):
                        row[k] *= ist
            continue
        for i in range(i0, i1):
            for j in range(j0, j1):
                for k in range(k0, k1):
                    c = w[i, j, k]
                    if c == 0:
                        continue
                    if inverse:
                        m = np.int32((abs(c) + BIAS) * st + 0.5)
                    else:
                        m = np.int32(abs(c) / st + ROUND)
                    w[i, j, k] = -m if c < 0 else m


@njit(cache=True, nogil=True)
def _quantise(w, n0, n1, n2, steps):
    _requant(w, n0, n1, n2, steps, False)


@njit(cache=True, nogil=True)
def quantise_level(details, shape, steps, first, stride):
    """Quantise the detail buffers of a level in place (the wavelet + zstd baseline)."""
    c0 = (shape[0] + TILE - 1) // TILE
    c1 = (shape[1] + TILE - 1) // TILE
    c2 = (shape[2] + TILE - 1) // TILE
    for t in range(first, c0 * c1 * c2, stride):
        _, _, _, _, _, _, n0, n1, n2 = _tile_box(t, c0, c1, shape)
        _quantise(details[t], n0, n1, n2, steps)


@njit(cache=True, nogil=True)
def _dequantise(w, n0, n1, n2, steps):
    _requant(w, n0, n1, n2, steps, True)


@njit(cache=True, nogil=True)
def _encode_tile(w, n0, n1, n2, coder, transform, lossless, out, base):
    if coder == CODER_RANS:
        return encode_rans(w, n0, n1, n2, False, out, base)
    if transform == TRANSFORM_HAAR:
        return encode_haar_arith(w, n0, n1, n2, out, base)
    return encode_arith(w, n0, n1, n2, False, out, base, lossless)


@njit(cache=True, nogil=True)
def encode_level(a, steps, coder, out, cap, sizes, low, tfs, choice, first, stride):
    """Forward-transform, quantise and encode every tile of ``a``; the lowpass goes to ``low``, tile ``t``'s bytes to
    ``out[t*cap : t*cap + sizes[t]]`` (``out`` zeroed) and its transform to ``tfs[t]``.

    Lossless levels (``steps[0] > 0``) code each tile with the 5/3 and with the S-transform (the arithmetic coder
    with its block-interleaved S-transform model, :func:`~.entropy.encode_haar_arith`) and keep the strictly smaller
    (the 5/3 on ties, so an all-zero 5/3 brick stays the 5/3's linear interpolation); lossy levels use the 5/3.
    ``choice`` >= 0 forces that transform on lossless levels (tests, comparisons); -1 chooses."""
    shape = a.shape
    c0 = (shape[0] + TILE - 1) // TILE
    c1 = (shape[1] + TILE - 1) // TILE
    c2 = (shape[2] + TILE - 1) // TILE
    lossless = steps[0] > 0
    alt = np.zeros(cap if lossless else 1, np.uint8)
    for t in range(first, c0 * c1 * c2, stride):
        t0, t1, t2, s0, s1, s2, n0, n1, n2 = _tile_box(t, c0, c1, shape)
        w = np.empty((TILE, TILE, TILE), np.int32)
        for i in range(n0):
            for j in range(n1):
                for k in range(n2):
                    w[i, j, k] = a[s0 + i, s1 + j, s2 + k]
        tf = TRANSFORM_53
        if lossless and choice == TRANSFORM_HAAR:
            haar_forward_tile(w, n0, n1, n2)
            sizes[t] = _encode_tile(w, n0, n1, n2, coder, TRANSFORM_HAAR, True, out, t * cap)
            tf = TRANSFORM_HAAR
        wh = w.copy() if lossless and choice < 0 else w
        size = sizes[t]
        if tf == TRANSFORM_53:
            forward_tile(w, n0, n1, n2)
            _quantise(w, n0, n1, n2, steps)
            size = _encode_tile(w, n0, n1, n2, coder, TRANSFORM_53, lossless, out, t * cap)
        if lossless and choice < 0 and size > 0:
            haar_forward_tile(wh, n0, n1, n2)
            size_h = _encode_tile(wh, n0, n1, n2, coder, TRANSFORM_HAAR, True, alt, 0)
            if size_h < size:
                for u in range(size):
                    out[t * cap + u] = 0
                for u in range(size_h):
                    out[t * cap + u] = alt[u]
                size = size_h
                tf = TRANSFORM_HAAR
                w = wh
            for u in range(size_h):
                alt[u] = 0
        sizes[t] = size
        tfs[t] = tf
        l0 = (n0 + 1) // 2
        l1 = (n1 + 1) // 2
        l2 = (n2 + 1) // 2
        for i in range(l0):
            for j in range(l1):
                for k in range(l2):
                    low[t0 * HALF + i, t1 * HALF + j, t2 * HALF + k] = w[i, j, k]


@njit(cache=True, nogil=True)
def decode_details(payload, offset, size, w, n0, n1, n2, coder, transform, lossless):
    """Entropy-decode one brick's details into the tile buffer ``w`` (lowpass already in place); 0 or -1."""
    if coder == CODER_RANS:
        return decode_rans(payload, offset, size, w, n0, n1, n2, False)
    if transform == TRANSFORM_HAAR:
        return decode_haar_arith(payload, offset, size, w, n0, n1, n2)
    return decode_arith(payload, offset, size, w, n0, n1, n2, False, lossless)


@njit(cache=True, nogil=True)
def decode_level(low, payload, offsets, sizes, tfs, valid, steps, coder, a, lo, hi, status, first, stride):
    """Inverse of :func:`encode_level`: tile ``t``'s bytes are ``payload[offsets[t]: offsets[t] + sizes[t]]``;
    tiles with ``valid[t] == 0`` (failed checksum) get zero details, i.e. the linear interpolation of the lowpass.
    ``status[t]`` is set to -1 where a stream turned out inconsistent (its details are then zeroed too).
    Samples are clipped to ``[lo, hi]`` on the way into ``a`` (of any integer dtype), so the finest level writes
    the caller's output type directly (no int32 volume, no separate conversion pass). ``tfs[t]``: the tile's
    transform (``TRANSFORM_53`` or ``TRANSFORM_HAAR``), from the brick table."""
    shape = a.shape
    c0 = (shape[0] + TILE - 1) // TILE
    c1 = (shape[1] + TILE - 1) // TILE
    c2 = (shape[2] + TILE - 1) // TILE
    w = np.empty((TILE, TILE, TILE), np.int32)
    tmp = np.empty((TILE, TILE, TILE), np.int32)
    for t in range(first, c0 * c1 * c2, stride):
        t0, t1, t2, s0, s1, s2, n0, n1, n2 = _tile_box(t, c0, c1, shape)
        l0 = (n0 + 1) // 2
        l1 = (n1 + 1) // 2
        l2 = (n2 + 1) // 2
        for i in range(l0):  # the lowpass first: the arithmetic coder's contexts read it
            for j in range(l1):
                src = low[t0 * HALF + i, t1 * HALF + j, t2 * HALF:t2 * HALF + l2]
                dst = w[i, j]
                for k in range(l2):
                    dst[k] = src[k]
        n = sizes[t] if valid[t] else 0
        rc = decode_details(payload, offsets[t], n, w, n0, n1, n2, coder, tfs[t], steps[0] > 0)
        status[t] = rc
        if rc != 0:
            decode_rans(payload, 0, 0, w, n0, n1, n2, False)  # zero the details
        _dequantise(w, n0, n1, n2, steps)
        inverse_tile_t(w, tmp, n0, n1, n2, tfs[t])
        for i in range(n0):
            for j in range(n1):
                src = w[i, j]
                dst = a[s0 + i, s1 + j, s2:s2 + n2]
                for k in range(n2):
                    dst[k] = min(max(src[k], lo), hi)


@njit(cache=True, nogil=True)
def encode_root(root, coder, out):
    """Code the root lowpass (<= 32^3 after DPCM by the caller) as one class-3 region; returns the byte count."""
    n0, n1, n2 = root.shape
    w = np.zeros((TILE, TILE, TILE), np.int32)
    w[:n0, :n1, :n2] = root
    if coder == CODER_RANS:
        return encode_rans(w, n0, n1, n2, True, out, 0)
    return encode_arith(w, n0, n1, n2, True, out, 0)


@njit(cache=True, nogil=True)
def decode_root(payload, offset, size, coder, root):
    n0, n1, n2 = root.shape
    w = np.zeros((TILE, TILE, TILE), np.int32)
    if coder == CODER_RANS:
        rc = decode_rans(payload, offset, size, w, n0, n1, n2, True)
    else:
        rc = decode_arith(payload, offset, size, w, n0, n1, n2, True)
    root[:, :, :] = w[:n0, :n1, :n2]
    return rc


@njit(cache=True, nogil=True)
def transform_level(a, low, details, tfs, first, stride):
    """Forward transform only (no coding): lowpass to ``low``, the full tile buffers (details in place) to
    ``details`` of shape (ntiles, TILE, TILE, TILE); tile ``t`` uses transform ``tfs[t]``. Used by the PSNR search
    (5/3 everywhere) and the node statistics (the transforms a file recorded)."""
    shape = a.shape
    c0 = (shape[0] + TILE - 1) // TILE
    c1 = (shape[1] + TILE - 1) // TILE
    c2 = (shape[2] + TILE - 1) // TILE
    for t in range(first, c0 * c1 * c2, stride):
        t0, t1, t2, s0, s1, s2, n0, n1, n2 = _tile_box(t, c0, c1, shape)
        w = details[t]
        for i in range(n0):
            for j in range(n1):
                for k in range(n2):
                    w[i, j, k] = a[s0 + i, s1 + j, s2 + k]
        forward_tile_t(w, n0, n1, n2, tfs[t])
        for i in range((n0 + 1) // 2):
            for j in range((n1 + 1) // 2):
                for k in range((n2 + 1) // 2):
                    low[t0 * HALF + i, t1 * HALF + j, t2 * HALF + k] = w[i, j, k]


@njit(cache=True, nogil=True)
def reconstruct_level(low, details, steps, a, quantise, first, stride):
    """(Quantise if ``quantise``, then) dequantise the stored details with ``steps`` and inverse-transform into
    ``a`` (PSNR search; the wavelet + zstd baseline)."""
    shape = a.shape
    c0 = (shape[0] + TILE - 1) // TILE
    c1 = (shape[1] + TILE - 1) // TILE
    c2 = (shape[2] + TILE - 1) // TILE
    for t in range(first, c0 * c1 * c2, stride):
        t0, t1, t2, s0, s1, s2, n0, n1, n2 = _tile_box(t, c0, c1, shape)
        w = details[t].copy()
        if quantise:
            _quantise(w, n0, n1, n2, steps)
        _dequantise(w, n0, n1, n2, steps)
        for i in range((n0 + 1) // 2):
            for j in range((n1 + 1) // 2):
                for k in range((n2 + 1) // 2):
                    w[i, j, k] = low[t0 * HALF + i, t1 * HALF + j, t2 * HALF + k]
        inverse_tile(w, n0, n1, n2)
        for i in range(n0):
            for j in range(n1):
                for k in range(n2):
                    a[s0 + i, s1 + j, s2 + k] = w[i, j, k]


@njit(cache=True, nogil=True)
def clip_cast(a, lo, hi, out, first, stride):
    """``out[i] = clip(a[i], lo, hi)`` over the planes ``first, first + stride, ...`` of axis 0 (3D arrays; the
    decoder's final conversion to the sample type, 4x faster than ``np.clip(...).astype``)."""
    for i in range(first, a.shape[0], stride):
        for j in range(a.shape[1]):
            for k in range(a.shape[2]):
                v = a[i, j, k]
                out[i, j, k] = lo if v < lo else (hi if v > hi else v)


THREADS = max(1, min(int(os.environ.get("VOLVIZ_THREADS", os.cpu_count() or 1)), 16))
_POOL: ThreadPoolExecutor | None = None


def run_tiles(kernel: Callable[..., Any], *args: Any) -> None:
    """Run ``kernel(*args, first, stride)`` on ``THREADS`` threads (the kernels release the GIL)."""
    global _POOL
    if THREADS == 1:
        kernel(*args, 0, 1)
        return
    if _POOL is None:
        _POOL = ThreadPoolExecutor(THREADS, thread_name_prefix="volviz-codec")
    futures = [_POOL.submit(kernel, *args, i, THREADS) for i in range(THREADS)]
    for f in futures:
        f.result()
