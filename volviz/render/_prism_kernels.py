"""Numba kernel of ``volviz.render.gl_fog``'s prism layers (PCP, Roettger §10.3): which terrain triangles make a
prism that the geometry shader (``resources/shaders/fog_prism_gs.glsl``) draws, by the shader's own test in the
same float32 arithmetic, and the layer's per-point buffer in one pass."""
from __future__ import annotations

import numpy as np
from numba import njit


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


@njit(cache=True, nogil=True)
def kept_connectivity(points: np.ndarray, values: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """The indices of the triangles ``tris`` (m, 3) that make a prism (``_keeps``), in their order, (3 k,) int32:
    the layer's index buffer."""
    m = tris.shape[0]
    out = np.empty(3 * m, dtype=np.int32)
    k = 0
    for i in range(m):
        a, b, c = tris[i, 0], tris[i, 1], tris[i, 2]
        if _keeps(points, values, a, b, c):
            out[k] = a
            out[k + 1] = b
            out[k + 2] = c
            k += 3
    return out[:k].copy()


@njit(cache=True, nogil=True)
def layer_buffer(points: np.ndarray, bottom: np.ndarray, top: np.ndarray, emission_bottom: np.ndarray,
                 emission_top: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """One pass of ``gl_fog.layer_values`` (its docstring): the box (lo, hi) of the points between bottom and top,
    the float32 points relative to the box's centre with the box's two corners appended, (n + 2, 3), and the
    float32 per-point values (n + 2, 4)."""
    n = points.shape[0]
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(n):
        lo[0] = min(lo[0], points[i, 0])
        hi[0] = max(hi[0], points[i, 0])
        lo[1] = min(lo[1], points[i, 1])
        hi[1] = max(hi[1], points[i, 1])
        lo[2] = min(lo[2], min(bottom[i], top[i]))
        hi[2] = max(hi[2], max(bottom[i], top[i]))
    centre = 0.5 * (lo + hi)
    rel = np.empty((n + 2, 3), np.float32)
    values = np.zeros((n + 2, 4), np.float32)
    for i in range(n):
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
