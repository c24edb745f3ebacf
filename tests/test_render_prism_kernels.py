"""The GPU fog prisms' per-point vertex buffer (``volviz.render.gl_fog.prism_buffers``, PCP, Roettger §10.3) and the
kernel that lists the prisms the geometry shader keeps (``volviz.render._prism_kernels.kept_connectivity``) against
NumPy formulations: values relative to the layer's centre, the box's corners for VTK's bounds, and a prism kept only
with area, thickness and some emission. The prisms' forms themselves are made by the geometry shader; its images
are checked against the CPU PCP in ``tests/test_render_gl_fog.py``."""
from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from volviz.nature.fog import FogLayer
from volviz.render._prism_kernels import kept_connectivity
from volviz.render.gl_fog import prism_buffers


def _layer(n: int = 400, seed: int = 3):
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-500.0, 1500.0, (n, 2)) + 1e5          # offset: the values are taken relative to the centre
    tris = Delaunay(xy).simplices.astype(np.int64)
    bottom = rng.uniform(100.0, 200.0, n)
    top = bottom + rng.uniform(-5.0, 40.0, n)               # some prisms have no thickness: left out
    points = np.column_stack([xy, bottom])
    return points, bottom, top, tris


def test_buffers_hold_the_points_values_and_box_relative_to_the_centre():
    points, bottom, top, tris = _layer()
    rng = np.random.default_rng(5)
    eb, et = rng.uniform(0, 2, len(bottom)), rng.uniform(0, 2, len(bottom))
    b = prism_buffers(points, bottom, top, tris, FogLayer(mode="emissive"), (eb, et))
    n = len(points)
    lo = np.array([points[:, 0].min(), points[:, 1].min(), min(bottom.min(), top.min())])
    hi = np.array([points[:, 0].max(), points[:, 1].max(), max(bottom.max(), top.max())])
    np.testing.assert_allclose(b.centre, 0.5 * (lo + hi), rtol=0, atol=1e-9)
    np.testing.assert_array_equal(b.points[:n, :2], (points[:, :2] - b.centre[:2]).astype(np.float32))
    v = b.attributes["fogValue"]
    np.testing.assert_array_equal(v[:n, 0], (bottom - b.centre[2]).astype(np.float32))
    np.testing.assert_array_equal(v[:n, 1], (top - b.centre[2]).astype(np.float32))
    np.testing.assert_array_equal(v[:n, 2:], np.column_stack([eb, et]).astype(np.float32))
    # the box's two corners close the points (in no triangle) so that VTK's bounds hold the layer's tops
    np.testing.assert_allclose(b.points[n:], np.stack([lo - b.centre, hi - b.centre]), atol=1e-3)
    np.testing.assert_allclose(b.bounds, np.stack([lo - b.centre, hi - b.centre], axis=1), atol=1e-9)
    thick = (top[tris] > bottom[tris]).any(axis=1)                        # all emit: the thick ones are kept
    np.testing.assert_array_equal(b.connectivity, tris[thick].reshape(-1))
    assert b.connectivity.max() < n


def test_prisms_are_kept_with_area_thickness_and_emission():
    points, bottom, top, tris = _layer()
    layer = FogLayer(color=(0.8, 0.8, 0.9), density=0.01, mode="emissive")
    ones = np.ones(len(bottom))
    buffers = prism_buffers(points, bottom, top, tris, layer, (ones, ones))
    thick = (top[tris] > bottom[tris]).any(axis=1)
    assert 0 < thick.sum() < len(tris)
    assert buffers.drawn == int(thick.sum())
    kept = kept_connectivity(buffers.points, buffers.attributes["fogValue"], tris)
    np.testing.assert_array_equal(kept, tris[thick].reshape(-1))
    np.testing.assert_array_equal(buffers.connectivity, tris[thick].reshape(-1))    # only the kept prisms drawn
    emission = (np.where(np.arange(len(bottom)) % 3 == 0, 1.0, 0.0), np.zeros(len(bottom)))
    some = prism_buffers(points, bottom, top, tris, layer, emission)
    assert some.drawn == int((thick & (emission[0][tris] > 0).any(axis=1)).sum())
    none = prism_buffers(points, bottom, top, tris, layer, (np.zeros(len(bottom)), np.zeros(len(bottom))))
    assert none.drawn == 0
    assert none.connectivity.shape == (0,)
    first = buffers.first_prism()
    assert first.drawn == 1 and np.array_equal(first.connectivity, tris[np.flatnonzero(thick)[0]])


def test_triangles_without_area_are_left_out():
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tris = np.array([[0, 1, 2], [0, 1, 3]])
    z = np.zeros(4)
    b = prism_buffers(points, z, z + 1.0, tris, FogLayer(mode="emissive"), (np.ones(4), np.ones(4)))
    assert b.drawn == 1 and np.array_equal(b.connectivity, [0, 1, 3])
    np.testing.assert_array_equal(kept_connectivity(b.points, b.attributes["fogValue"], tris), [0, 1, 3])
