"""Vectorised multilinear lookups into regularly sampled tables (the texture-filtering part of every table)."""
from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _coord(x, lo, step, n):
    """Fractional index of x on a grid lo + i·step, clamped to [0, n − 1]; returns (i0, w)."""
    f = (x - lo) / step if step > 0.0 else 0.0
    if f <= 0.0:
        return 0, 0.0
    if f >= n - 1:
        return n - 2 if n > 1 else 0, 1.0 if n > 1 else 0.0
    i0 = int(math.floor(f))
    return i0, f - i0


@numba.njit(cache=True, nogil=True, parallel=True)
def bilinear(table, lo, step, s_f, s_b, out):
    """out[m, :] = bilinear sample of table (n, n, c) at (s_f[m], s_b[m]); NaN scalars give 0."""
    n = table.shape[0]
    c = table.shape[2]
    for m in numba.prange(s_f.shape[0]):
        if s_f[m] != s_f[m] or s_b[m] != s_b[m]:
            for ch in range(c):
                out[m, ch] = 0.0
            continue
        i, wi = _coord(s_f[m], lo, step, n)
        j, wj = _coord(s_b[m], lo, step, n)
        i1 = min(i + 1, n - 1)
        j1 = min(j + 1, n - 1)
        for ch in range(c):
            out[m, ch] = ((1 - wi) * ((1 - wj) * table[i, j, ch] + wj * table[i, j1, ch])
                          + wi * ((1 - wj) * table[i1, j, ch] + wj * table[i1, j1, ch]))


@numba.njit(cache=True, nogil=True, parallel=True)
def trilinear(table, lo, step, dl, s_f, s_b, length, out):
    """out[m, :] = trilinear sample of table (n, n, L, c) at (s_f, s_b, length); l clamps to [0, (L−1)·dl]."""
    n = table.shape[0]
    nl = table.shape[2]
    c = table.shape[3]
    for m in numba.prange(s_f.shape[0]):
        if s_f[m] != s_f[m] or s_b[m] != s_b[m] or length[m] != length[m]:
            for ch in range(c):
                out[m, ch] = 0.0
            continue
        i, wi = _coord(s_f[m], lo, step, n)
        j, wj = _coord(s_b[m], lo, step, n)
        k, wk = _coord(length[m], 0.0, dl, nl)
        i1 = min(i + 1, n - 1)
        j1 = min(j + 1, n - 1)
        k1 = min(k + 1, nl - 1)
        for ch in range(c):
            a = (1 - wk) * table[i, j, k, ch] + wk * table[i, j, k1, ch]
            b = (1 - wk) * table[i, j1, k, ch] + wk * table[i, j1, k1, ch]
            cc = (1 - wk) * table[i1, j, k, ch] + wk * table[i1, j, k1, ch]
            d = (1 - wk) * table[i1, j1, k, ch] + wk * table[i1, j1, k1, ch]
            out[m, ch] = (1 - wi) * ((1 - wj) * a + wj * b) + wi * ((1 - wj) * cc + wj * d)


def flat_args(*arrays: object) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """Broadcast float64 arguments and return (shape, contiguous 1-D views)."""
    b = np.broadcast_arrays(*[np.asarray(a, dtype=np.float64) for a in arrays])
    return b[0].shape, [np.ascontiguousarray(x).ravel() for x in b]
