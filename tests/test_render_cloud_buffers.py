"""The clouds' GPU vertex buffer (``volviz.render.gl_nature.cloud_buffers``, its Numba kernel
``volviz.render._cloud_buffer_kernels``; Roettger §11.3-11.6 drawn by the GPU PT pass) against the NumPy
formulation of the same quantities: gl_pt's cell attributes (face planes, scalar form, scalar range), the modulation
form solved per cell with ``numpy.linalg.solve``, each repeated at the cell's 4 vertices, and the TF's culling of
``volviz.unstructured.topology.visible_cells``."""
from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from volviz.model.datasets import TetMesh
from volviz.nature.clouds import CloudShading
from volviz.render.gl_nature import cloud_buffers
from volviz.render.gl_pt import _cell_attributes
from volviz.unstructured.topology import topology, visible_cells


def _mesh(n: int = 300, seed: int = 2) -> tuple[TetMesh, np.ndarray]:
    rng = np.random.default_rng(seed)
    pts = rng.uniform(0.0, 50.0, (n, 3)) + [1e4, 2e4, 110.0]        # far from the origin, as the cloud deck
    tets = Delaunay(pts).simplices
    tets[::2] = tets[::2][:, [0, 1, 3, 2]]                            # both orientations
    return TetMesh(pts, tets, rng.uniform(0.0, 1.0, n)), rng.uniform(0.2, 1.0, n)


def test_buffer_matches_the_numpy_attributes_at_every_vertex():
    mesh, modulation = _mesh()
    b = cloud_buffers(mesh, modulation, CloudShading.npr())
    topo = topology(mesh)
    np.testing.assert_array_equal(b.points, topo.points[topo.tets].reshape(-1, 3).astype(np.float32))
    expected = _cell_attributes(mesh)
    p = topo.points[topo.tets]
    v = modulation[topo.tets]
    g = np.linalg.solve(p[:, 1:] - p[:, :1], (v[:, 1:] - v[:, :1])[..., None])[..., 0]
    expected["ptModulate"] = np.concatenate([g, (v[:, 0] - np.einsum("ij,ij->i", g, p[:, 0]))[:, None]], axis=1)
    assert set(b.attributes) == set(expected)
    for name, cell in expected.items():
        got = b.attributes[name]
        assert got.shape == (4 * len(cell), 4) and got.dtype == np.float32
        scale = np.abs(cell).max()
        np.testing.assert_allclose(got, np.repeat(cell, 4, axis=0), rtol=1e-5, atol=1e-6 * scale, err_msg=name)


def test_culling_matches_visible_cells():
    mesh, modulation = _mesh(seed=4)
    shading = CloudShading.npr(cutoff=0.5)                   # a TF that is zero below 0.5
    b = cloud_buffers(mesh, modulation, shading)
    expected = visible_cells(mesh, shading.tf.scalars, shading.tf.extinction)
    assert 0 < expected.sum() < len(expected)
    np.testing.assert_array_equal(b.visible, expected)
