"""Numba kernel of ``volviz.render.gl_fog``'s prism layers (PCP, Roettger §10.3): which terrain triangles make a
prism that the geometry shader (``resources/shaders/fog_prism_gs.glsl``) draws, by the shader's own test in the
same float32 arithmetic."""
from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, nogil=True, parallel=True)
def kept_triangles(points: np.ndarray, values: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """(m,) bool: triangle ``tris[i]`` of float32 ``points`` (n, 3; x, y used) with float32 per-point ``values``
    (n, 4: bottom height, top height, bottom emission, top emission) has a non-zero area, some thickness (top above
    bottom at a vertex) and some emission (one of its six emissions > 0): the prisms §10.3 keeps ("zero-emission
    cells were discarded")."""
    m = tris.shape[0]
    out = np.zeros(m, dtype=np.bool_)
    for i in prange(m):
        a, b, c = tris[i, 0], tris[i, 1], tris[i, 2]
        e1x, e1y = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
        e2x, e2y = points[c, 0] - points[a, 0], points[c, 1] - points[a, 1]
        det = e1x * e2y - e2x * e1y
        thick = values[a, 1] > values[a, 0] or values[b, 1] > values[b, 0] or values[c, 1] > values[c, 0]
        emits = False
        for j in (a, b, c):
            if values[j, 2] > 0.0 or values[j, 3] > 0.0:
                emits = True
        out[i] = det != 0.0 and thick and emits
    return out
