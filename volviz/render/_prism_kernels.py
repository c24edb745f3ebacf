"""Numba kernel of ``volviz.render.gl_fog``'s prism layers (PCP, Roettger §10.3): which terrain triangles make a
prism that the geometry shader (``resources/shaders/fog_prism_gs.glsl``) draws, by the shader's own test in the
same float32 arithmetic, and the layer's per-point buffer in one pass."""
from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, nogil=True, inline="always")
def _keeps(points: np.ndarray, values: np.ndarray, a: int, b: int, c: int) -> bool:
    """Whether triangle (a, b, c) of float32 ``points`` (n, 3; x, y used) with float32 per-point ``values`` (n, 4:
    bottom height, top height, bottom emission, top emission) has a non-zero area, some thickness (top above bottom
    at a vertex) and some emission (one of its six emissions > 0): the prisms §10.3 keeps ("zero-emission cells were
    discarded")."""
    e1x, e1y = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
    e2x, e2y = points[c, 0] - points[a, 0], points[c, 1] - points[a, 1]
    det = e1x * e2y - e2x * e1y
    thick = values[a, 1] > values[a, 0] or values[b, 1] > values[b, 0] or values[c, 1] > values[c, 0]
    emits = False
    for j in (a, b, c):
        if values[j, 2] > 0.0 or values[j, 3] > 0.0:
            emits = True
    return det != 0.0 and thick and emits


#: chunks of the points or triangles that the kernels deal out to their threads
CHUNKS = 64


@njit(cache=True, nogil=True, parallel=True)
def kept_connectivity(points: np.ndarray, values: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """The indices of the triangles ``tris`` (m, 3) that make a prism (``_keeps``), in their order, (3 k,) int32:
    the layer's index buffer (tested and counted, then written at each chunk's offset, per chunk in parallel)."""
    m = tris.shape[0]
    keep = np.empty(m, dtype=np.bool_)
    start = np.zeros(CHUNKS + 1, dtype=np.int64)
    for chunk in prange(CHUNKS):
        c = 0
        for i in range(chunk * m // CHUNKS, (chunk + 1) * m // CHUNKS):
            keep[i] = _keeps(points, values, tris[i, 0], tris[i, 1], tris[i, 2])
            c += keep[i]
        start[chunk + 1] = c
    for chunk in range(CHUNKS):
        start[chunk + 1] += start[chunk]
    out = np.empty(3 * start[CHUNKS], dtype=np.int32)
    for chunk in prange(CHUNKS):
        k = 3 * start[chunk]
        for i in range(chunk * m // CHUNKS, (chunk + 1) * m // CHUNKS):
            if keep[i]:
                out[k] = tris[i, 0]
                out[k + 1] = tris[i, 1]
                out[k + 2] = tris[i, 2]
                k += 3
    return out


@njit(cache=True, nogil=True, parallel=True)
def layer_buffer(points: np.ndarray, bottom: np.ndarray, top: np.ndarray, emission_bottom: np.ndarray,
                 emission_top: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """One pass of ``gl_fog.layer_values`` (its docstring; the box per chunk of points, then the buffers, in
    parallel): the box (lo, hi) of the points between bottom and top, the float32 points relative to the box's
    centre with the box's two corners appended, (n + 2, 3), and the float32 per-point values (n + 2, 4)."""
    n = points.shape[0]
    box = np.empty((CHUNKS, 6))
    for chunk in prange(CHUNKS):
        lo0 = lo1 = lo2 = np.inf
        hi0 = hi1 = hi2 = -np.inf
        for i in range(chunk * n // CHUNKS, (chunk + 1) * n // CHUNKS):
            lo0 = min(lo0, points[i, 0])
            hi0 = max(hi0, points[i, 0])
            lo1 = min(lo1, points[i, 1])
            hi1 = max(hi1, points[i, 1])
            lo2 = min(lo2, min(bottom[i], top[i]))
            hi2 = max(hi2, max(bottom[i], top[i]))
        box[chunk, 0], box[chunk, 1], box[chunk, 2] = lo0, lo1, lo2
        box[chunk, 3], box[chunk, 4], box[chunk, 5] = hi0, hi1, hi2
    lo = np.zeros(3)
    hi = np.zeros(3)
    if n > 0:                                  # no points: an empty box at the origin
        for a in range(3):
            lo[a] = box[:, a].min()
            hi[a] = box[:, 3 + a].max()
    centre = 0.5 * (lo + hi)
    rel = np.empty((n + 2, 3), np.float32)
    values = np.zeros((n + 2, 4), np.float32)
    for i in prange(n):
        rel[i, 0] = points[i, 0] - centre[0]
        rel[i, 1] = points[i, 1] - centre[1]
        zb = np.float32(bottom[i] - centre[2])
        rel[i, 2] = zb
        values[i, 0] = zb
        values[i, 1] = top[i] - centre[2]
        values[i, 2] = emission_bottom[i]
        values[i, 3] = emission_top[i]
    for a in range(3):
        rel[n, a] = lo[a] - centre[a]
        rel[n + 1, a] = hi[a] - centre[a]
    return lo, hi, rel, values
