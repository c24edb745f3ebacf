"""The clouds' GPU vertex buffer (``volviz.render.gl_nature.cloud_buffers``, its Numba kernel
``volviz.render._cloud_buffer_kernels.leaf_vertex_buffer``; Roettger §11.3-11.6 drawn by the GPU PT pass) against the
NumPy formulation of the same quantities: the frame's tetrahedral mesh in back-to-front order
(``CloudFrame.to_tetmesh``), gl_pt's cell attributes of it (face planes, scalar form, scalar range), the modulation
form solved per cell with ``numpy.linalg.solve``, the positions at the cell's 4 vertices, and the TF's culling of
``volviz.unstructured.topology.visible_cells``."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.camera import Camera
from volviz.nature import noise
from volviz.nature.clouds import CloudLOD, CloudShading, CloudVolume
from volviz.render.gl_nature import cloud_buffers, modulation_scale
from volviz.render.gl_pt import _cell_attributes
from volviz.unstructured.topology import topology, visible_cells

EYES = [(-8.1, -12.4, 14.3), (30.0, 9.0, 3.0), (6.0, 5.0, 4.5)]     # outside, beside, inside the volume


def _frame(eye, shading):
    shape = (17, 17, 9)
    f = noise.cloud_density(shape, seed=2, coverage=0.4)
    g = noise.cloud_light(f, (1.5, 1.5, 1.5))
    vol = CloudVolume(f, g, (1.5, 1.5, 1.5), (1e4, -2e4, 110.0))   # far from the origin, as a cloud deck
    lod = CloudLOD(vol, big_c=2.5, small_c=4.0, cutoff=shading.cutoff)
    eye = np.asarray(eye) * 1.5 + vol.origin
    cam = Camera(eye, np.asarray(vol.origin) + [12.0, 12.0, 6.0], (0, 0, 1), 50, clipping_range=(0.5, 200))
    return lod.update(cam, (48, 36)), vol, eye


@pytest.mark.parametrize("eye", EYES)
@pytest.mark.parametrize("table_field", ["f", "gamma"])
def test_buffers_match_the_numpy_cell_attributes(eye, table_field):
    shading = CloudShading.npr() if table_field == "f" else CloudShading.physical()
    frame, vol, eye = _frame(eye, shading)
    assert frame.n_tets > 50 and len(np.unique(frame.leaves[:, 0])) > 1        # leaves of several levels
    m_scale = modulation_scale(vol, shading)
    b = cloud_buffers(frame, shading, eye, m_scale)
    mesh, other = frame.to_tetmesh(shading.table_field, eye=eye)
    topo = topology(mesh)
    assert b.n_tets == mesh.n_cells
    np.testing.assert_allclose(b.points.astype(np.float64) + b.centre,
                               (topo.points + topo.origin)[topo.tets].reshape(-1, 3), rtol=0, atol=1e-3)
    expected = _cell_attributes(mesh)
    p = topo.points[topo.tets]
    v = (other / m_scale)[topo.tets]
    g = np.linalg.solve(p[:, 1:] - p[:, :1], (v[:, 1:] - v[:, :1])[..., None])[..., 0]
    c = v[:, 0] - np.einsum("ij,ij->i", g, p[:, 0] + topo.origin - b.centre)   # the form relative to b.centre
    expected["ptModulate"] = np.concatenate([g, c[:, None]], axis=1)
    s = mesh.scalars[topo.tets]
    gs = expected["ptScalar"][:, :3].astype(np.float64)
    expected["ptScalar"] = np.concatenate([gs, (s[:, 0] - np.einsum("ij,ij->i", gs, p[:, 0] + topo.origin
                                                                     - b.centre))[:, None]], axis=1)
    for f in range(4):                                   # planes n . x = d relative to b.centre
        n = expected[f"ptPlane{f}"][:, :3].astype(np.float64)
        d = expected[f"ptPlane{f}"][:, 3] + np.einsum("ij,j->i", n, topo.origin - b.centre)
        expected[f"ptPlane{f}"] = np.concatenate([n, d[:, None]], axis=1)
    names = [f"ptPlane{f}" for f in range(4)] + ["ptScalar", "ptRange", "ptModulate"]
    assert b.cells.shape == (mesh.n_cells, 7, 4) and b.cells.dtype == np.float32
    for k, name in enumerate(names):
        cell = expected[name]
        scale = max(np.abs(cell).max(), 1e-12)
        np.testing.assert_allclose(b.cells[:, k], cell, rtol=1e-5, atol=1e-5 * scale, err_msg=name)


def test_culling_matches_visible_cells():
    shading = CloudShading.npr(cutoff=0.3)
    frame, vol, eye = _frame(EYES[0], shading)
    b = cloud_buffers(frame, shading, eye, modulation_scale(vol, shading))
    mesh, _ = frame.to_tetmesh(shading.table_field, eye=eye)
    expected = visible_cells(mesh, shading.tf.scalars, shading.tf.extinction)
    assert 0 < expected.sum() < len(expected)
    np.testing.assert_array_equal(b.visible, expected)
