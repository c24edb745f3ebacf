"""The Numba kernels of the GPU fog prisms' vertex buffers (``volviz.render._prism_kernels``, PCP, Roettger §10.3)
against NumPy formulations of the same quantities: the affine forms by solving each triangle's 3x3 system, the side
planes through their edges and positive at the opposite vertex, the triangles wound away from the prism's centroid,
and the buffers as the forms repeated at the six vertices."""
from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from volviz.nature.fog import FogLayer
from volviz.render._prism_kernels import PRISM_TRIANGLES, expand_buffers, prism_forms
from volviz.render.gl_fog import prism_attributes, prism_buffers


def _layer(n: int = 400, seed: int = 3):
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-500.0, 1500.0, (n, 2)) + 1e5          # offset: the forms are taken relative to the centre
    tris = Delaunay(xy).simplices.astype(np.int64)
    bottom = rng.uniform(100.0, 200.0, n)
    top = bottom + rng.uniform(-5.0, 40.0, n)               # some prisms have no thickness: left out
    points = np.column_stack([xy, bottom])
    return points, bottom, top, tris


def test_forms_corners_and_faces_match_numpy():
    points, bottom, top, tris = _layer()
    rng = np.random.default_rng(5)
    centre = np.array([1e5 + 500.0, 1e5 + 500.0, 150.0])
    xy = np.ascontiguousarray(points[:, :2] - centre[:2])
    values = np.stack([bottom - centre[2], top - centre[2], rng.uniform(0, 2, len(bottom)),
                       rng.uniform(0, 2, len(bottom))])
    forms, corners, faces = prism_forms(xy, tris, values, centre)

    t = xy[tris]
    a = np.concatenate([t, np.ones(t.shape[:2] + (1,))], axis=2)
    for f in range(4):
        expected = np.linalg.solve(a, values[f][tris][..., None])[..., 0]
        np.testing.assert_allclose(forms[:, 3 + f], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    for e in range(3):
        plane = forms[:, e]
        at = lambda v: plane[:, 0] * t[:, v, 0] + plane[:, 1] * t[:, v, 1] + plane[:, 2]  # noqa: E731
        scale = np.abs(plane[:, :2]).max(axis=1) * 2000.0
        assert np.all(np.abs(at(e)) <= 1e-9 * scale) and np.all(np.abs(at((e + 1) % 3)) <= 1e-9 * scale)
        assert np.all(at((e + 2) % 3) > 0)                 # the opposite vertex is inside
    np.testing.assert_array_equal(corners[:, :3, :2], t)
    np.testing.assert_array_equal(corners[:, :3, 2], values[0][tris])
    np.testing.assert_array_equal(corners[:, 3:, 2], values[1][tris])
    v = corners[np.arange(len(tris))[:, None, None], faces]                # (k, 8, 3, 3)
    normal = np.cross(v[:, :, 1] - v[:, :, 0], v[:, :, 2] - v[:, :, 0])
    outward = np.einsum("kfj,kfj->kf", normal, v.mean(axis=2) - corners.mean(axis=1)[:, None])
    assert np.all(outward >= 0)
    assert np.all(np.sort(faces, axis=2) == np.sort(PRISM_TRIANGLES, axis=1))   # the same triangles, rewound

    pts32, attrs32, conn = expand_buffers(forms, corners, faces)
    np.testing.assert_array_equal(pts32, corners.reshape(-1, 3).astype(np.float32))
    for f in range(7):
        np.testing.assert_array_equal(attrs32[f], np.repeat(forms[:, f], 6, axis=0).astype(np.float32))
    np.testing.assert_array_equal(conn, (faces + 6 * np.arange(len(tris))[:, None, None]).reshape(-1))


def test_prism_buffers_keep_only_prisms_with_thickness_and_emission():
    points, bottom, top, tris = _layer()
    layer = FogLayer(color=(0.8, 0.8, 0.9), density=0.01, mode="emissive")
    idx, centre, attrs = prism_attributes(points, bottom, top, tris, np.ones(len(bottom)), np.ones(len(bottom)))
    thick = (top[tris] > bottom[tris]).any(axis=1)
    np.testing.assert_array_equal(idx, np.flatnonzero(thick))
    buffers = prism_buffers(points, bottom, top, tris, layer, (np.ones(len(bottom)), np.ones(len(bottom))))
    assert buffers.drawn == len(idx) and buffers.points.shape == (6 * len(idx), 3)
    np.testing.assert_array_equal(buffers.attributes["fogTop"], np.repeat(attrs["fogTop"], 6, axis=0)
                                  .astype(np.float32))
    none = prism_buffers(points, bottom, top, tris, layer, (np.zeros(len(bottom)), np.zeros(len(bottom))))
    assert none.drawn == 0 and none.points.shape == (0, 3) and none.connectivity.shape == (0,)
