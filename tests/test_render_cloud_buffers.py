"""The clouds' GPU buffers (``volviz.render.gl_nature.cloud_buffers``, its Numba kernel
``volviz.render._cloud_buffer_kernels.leaf_buffer``; Roettger §11.3-11.6 drawn by the GPU PT pass): per leaf its
lowest grid point and edge, its corners' morphed table field and modulating field (the values the geometry shader
makes the leaf's tetrahedra from), exactly as the frame holds them, its lowest corner's position, and the TF's
culling against ``volviz.unstructured.topology.visible_cells`` of the frame's tetrahedral mesh
(``CloudFrame.to_tetmesh``, 5 tetrahedra per leaf in leaf order). The tetrahedra the shader makes are checked by
their images against the CPU clouds in ``tests/test_render_gl_nature.py``."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.camera import Camera
from volviz.nature import noise
from volviz.nature.clouds import CloudLOD, CloudShading, CloudVolume
from volviz.render.gl_nature import cloud_buffers, modulation_scale
from volviz.unstructured.topology import visible_cells

EYES = [(-8.1, -12.4, 14.3), (30.0, 9.0, 3.0), (6.0, 5.0, 4.5)]     # outside, beside, inside the volume


def _frame(eye, shading, lod_cutoff=None):
    shape = (17, 17, 9)
    f = noise.cloud_density(shape, seed=2, coverage=0.4)
    g = noise.cloud_light(f, (1.5, 1.5, 1.5))
    vol = CloudVolume(f, g, (1.5, 1.5, 1.5), (1e4, -2e4, 110.0))   # far from the origin, as a cloud deck
    lod = CloudLOD(vol, big_c=2.5, small_c=4.0, cutoff=shading.cutoff if lod_cutoff is None else lod_cutoff)
    eye = np.asarray(eye) * 1.5 + vol.origin
    cam = Camera(eye, np.asarray(vol.origin) + [12.0, 12.0, 6.0], (0, 0, 1), 50, clipping_range=(0.5, 200))
    return lod.update(cam, (48, 36)), vol


@pytest.mark.parametrize("eye", EYES)
@pytest.mark.parametrize("table_field", ["f", "gamma"])
def test_leaf_texels_hold_the_morphed_corner_values(eye, table_field):
    shading = CloudShading.npr() if table_field == "f" else CloudShading.physical()
    frame, vol = _frame(eye, shading)
    assert frame.n_tets > 50 and len(np.unique(frame.leaves[:, 0])) > 1        # leaves of several levels
    m_scale = modulation_scale(vol, shading)
    b = cloud_buffers(frame, shading, m_scale)
    vf, vg = frame.lod.morphed
    table, other = (vf, vg) if table_field == "f" else (vg, vf)
    assert b.n_leaves == len(frame.leaves) and b.texels.shape == (b.n_leaves, 5, 4)
    assert b.texels.dtype == np.float32 and b.points.dtype == np.float32
    s = vol.root >> frame.leaves[:, 0]
    low = frame.leaves[:, 1:] * s[:, None]
    np.testing.assert_array_equal(b.texels[:, 0], np.concatenate([low, s[:, None]], axis=1))
    for q in range(8):
        corner = low + np.array([(q >> 2) & 1, (q >> 1) & 1, q & 1]) * s[:, None]
        at = tuple(corner.T)
        np.testing.assert_array_equal(b.texels[:, 1 + q // 4, q % 4], table[at].astype(np.float32))
        np.testing.assert_array_equal(b.texels[:, 3 + q // 4, q % 4], (other[at] / m_scale).astype(np.float32))
    spacing = np.asarray(vol.spacing)
    np.testing.assert_allclose(b.points[:-2].astype(np.float64) + b.centre, np.asarray(vol.origin) + low * spacing,
                               rtol=0, atol=1e-3)
    np.testing.assert_allclose(b.origin + b.centre, vol.origin)
    np.testing.assert_array_equal(b.points[-2:], b.bounds.T.astype(np.float32))      # the box, for VTK's bounds


def test_culling_keeps_the_leaves_with_a_visible_tetrahedron():
    shading = CloudShading.npr(cutoff=0.3)
    frame, vol = _frame(EYES[0], shading, lod_cutoff=0.0)     # leaves the TF hides in part or wholly
    b = cloud_buffers(frame, shading, modulation_scale(vol, shading))
    mesh, _ = frame.to_tetmesh(shading.table_field, eye=EYES[0])
    expected = visible_cells(mesh, shading.tf.scalars, shading.tf.extinction).reshape(-1, 5).any(axis=1)
    assert 0 < expected.sum() < len(expected)
    np.testing.assert_array_equal(b.visible, expected)
