"""Numba kernels of ``volviz.render.gl_fog``'s prism vertex buffers (PCP, Roettger §10.3): per prism of a fog or
cloud layer, the three side planes, the affine forms of its bottom and top heights and emissions over the prism's
triangle, its six corners and its eight triangles wound outward; then each prism's forms repeated at its six
vertices as the float32 attributes the fragment shader reads. One prism per iteration, in parallel."""
from __future__ import annotations

import numpy as np
from numba import njit, prange

#: the 8 triangles of a prism (vertices 0-2 bottom, 3-5 top), before each is wound outward
PRISM_TRIANGLES = np.array([[0, 2, 1], [3, 4, 5], [0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [2, 0, 3], [2, 3, 5]],
                           dtype=np.int64)
N_FORMS = 7   # fogSide0..2, fogBottom, fogTop, fogEmBottom, fogEmTop


@njit(cache=True, nogil=True, parallel=True)
def prism_forms(xy: np.ndarray, tris: np.ndarray, values: np.ndarray, centre: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For triangles ``tris`` (k, 3) of points ``xy`` (n, 2, relative to the layer's centre) and per-point ``values``
    (4, n: bottom height, top height, bottom emission, top emission; heights relative to ``centre[2]``):

    - ``forms`` (k, 7, 3) float64: side planes (nx, ny, d), nx x + ny y + d >= 0 inside (the normal of each edge
      turned towards the opposite vertex), then (gx, gy, c) with gx x + gy y + c = value at the three vertices for
      each of the four values (Cramer's rule on the triangle; its doubled area is the determinant, non-zero for the
      prisms kept);
    - ``corners`` (k, 6, 3) float64: bottom then top corners, relative to the centre;
    - ``faces`` (k, 8, 3) int64: ``PRISM_TRIANGLES`` with each triangle wound so that its normal points away from
      the prism's centroid."""
    k = tris.shape[0]
    forms = np.empty((k, N_FORMS, 3))
    corners = np.empty((k, 6, 3))
    faces = np.empty((k, 8, 3), dtype=np.int64)
    for p in prange(k):
        i0, i1, i2 = tris[p, 0], tris[p, 1], tris[p, 2]
        x = (xy[i0, 0], xy[i1, 0], xy[i2, 0])
        y = (xy[i0, 1], xy[i1, 1], xy[i2, 1])
        for e in range(3):
            a, b, c = e, (e + 1) % 3, (e + 2) % 3
            nx, ny = -(y[b] - y[a]), x[b] - x[a]
            if nx * (x[c] - x[a]) + ny * (y[c] - y[a]) < 0.0:
                nx, ny = -nx, -ny
            forms[p, e, 0] = nx
            forms[p, e, 1] = ny
            forms[p, e, 2] = -(nx * x[a] + ny * y[a])
        x10, y10, x20, y20 = x[1] - x[0], y[1] - y[0], x[2] - x[0], y[2] - y[0]
        det = x10 * y20 - x20 * y10
        for f in range(4):
            v0, v1, v2 = values[f, i0], values[f, i1], values[f, i2]
            gx = ((v1 - v0) * y20 - (v2 - v0) * y10) / det
            gy = (x10 * (v2 - v0) - x20 * (v1 - v0)) / det
            forms[p, 3 + f, 0] = gx
            forms[p, 3 + f, 1] = gy
            forms[p, 3 + f, 2] = v0 - gx * x[0] - gy * y[0]
        mx = my = mz = 0.0
        for j in range(3):
            idx = tris[p, j]
            corners[p, j, 0] = corners[p, j + 3, 0] = xy[idx, 0]
            corners[p, j, 1] = corners[p, j + 3, 1] = xy[idx, 1]
            corners[p, j, 2] = values[0, idx]
            corners[p, j + 3, 2] = values[1, idx]
        for j in range(6):
            mx += corners[p, j, 0] / 6.0
            my += corners[p, j, 1] / 6.0
            mz += corners[p, j, 2] / 6.0
        for f in range(8):
            a, b, c = PRISM_TRIANGLES[f, 0], PRISM_TRIANGLES[f, 1], PRISM_TRIANGLES[f, 2]
            ux, uy, uz = (corners[p, b, 0] - corners[p, a, 0], corners[p, b, 1] - corners[p, a, 1],
                          corners[p, b, 2] - corners[p, a, 2])
            wx, wy, wz = (corners[p, c, 0] - corners[p, a, 0], corners[p, c, 1] - corners[p, a, 1],
                          corners[p, c, 2] - corners[p, a, 2])
            nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
            fx = (corners[p, a, 0] + corners[p, b, 0] + corners[p, c, 0]) / 3.0 - mx
            fy = (corners[p, a, 1] + corners[p, b, 1] + corners[p, c, 1]) / 3.0 - my
            fz = (corners[p, a, 2] + corners[p, b, 2] + corners[p, c, 2]) / 3.0 - mz
            if nx * fx + ny * fy + nz * fz < 0.0:
                a, c = c, a
            faces[p, f, 0] = a
            faces[p, f, 1] = b
            faces[p, f, 2] = c
    return forms, corners, faces


@njit(cache=True, nogil=True, parallel=True)
def expand_buffers(forms: np.ndarray, corners: np.ndarray, faces: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The vertex buffer of ``prism_forms``' prisms: points (6k, 3) float32, attributes (7, 6k, 3) float32 (each
    prism's forms at its six vertices), connectivity (24k,) int64 (vertex indices of the 8 triangles per prism)."""
    k = forms.shape[0]
    points = np.empty((6 * k, 3), dtype=np.float32)
    attributes = np.empty((N_FORMS, 6 * k, 3), dtype=np.float32)
    connectivity = np.empty(24 * k, dtype=np.int64)
    for p in prange(k):
        for j in range(6):
            for c in range(3):
                points[6 * p + j, c] = corners[p, j, c]
            for f in range(N_FORMS):
                for c in range(3):
                    attributes[f, 6 * p + j, c] = forms[p, f, c]
        for f in range(8):
            for c in range(3):
                connectivity[24 * p + 3 * f + c] = 6 * p + faces[p, f, c]
    return points, attributes, connectivity
