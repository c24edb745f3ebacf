"""What the GPU clouds are made from (``volviz.render.gl_nature``; Roettger §11.3-11.6 drawn by the GPU PT pass, the
morph on the GPU): the frame's leaves without the CPU morph (``CloudLOD.update(morph=False)``: the same refinement,
the same back-to-front order, plus the leaves the morphed-corner test would drop), the refinement thresholds the
vertex shader tests the eye against (``CloudLOD.refinement_thresholds``: Eq. 11.1 in closed form, the same
decision as ``decide``), the grid's field texels, and the TF's visible intervals the geometry shader culls with
(``visible_ranges``'s decision). The morph itself is checked by its images against the CPU clouds in
``tests/test_render_gl_nature.py``."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.camera import Camera
from volviz.nature import noise
from volviz.nature.clouds import CloudLOD, CloudShading, CloudVolume
from volviz.optics import TransferFunction
from volviz.render.gl_nature import _visible_intervals, cloud_field_texels, cloud_leaves, modulation_scale
from volviz.unstructured.topology import visible_ranges

EYES = [(-8.1, -12.4, 14.3), (30.0, 9.0, 3.0), (6.0, 5.0, 4.5)]     # outside, beside, inside the volume


def _lod(cutoff: float) -> tuple[CloudLOD, CloudVolume]:
    shape = (17, 17, 9)
    f = noise.cloud_density(shape, seed=2, coverage=0.4)
    g = noise.cloud_light(f, (1.5, 1.5, 1.5))
    vol = CloudVolume(f, g, (1.5, 1.5, 1.5), (1e4, -2e4, 110.0))   # far from the origin, as a cloud deck
    return CloudLOD(vol, big_c=2.5, small_c=4.0, cutoff=cutoff), vol


def _camera(eye, vol) -> Camera:
    eye = np.asarray(eye) * 1.5 + vol.origin
    return Camera(eye, np.asarray(vol.origin) + [12.0, 12.0, 6.0], (0, 0, 1), 50, clipping_range=(0.5, 200))


@pytest.mark.parametrize("eye", EYES)
def test_unmorphed_frames_list_the_same_refinement(eye):
    lod, vol = _lod(CloudShading.npr().cutoff)
    cam = _camera(eye, vol)
    morphed = lod.update(cam, (48, 36)).leaves
    state = lod._state.copy()
    plain = lod.update(cam, (48, 36), morph=False).leaves
    np.testing.assert_array_equal(lod._state, state)               # the same nodes refined
    assert len(morphed) > 10 and len(np.unique(morphed[:, 0])) > 1    # leaves of several levels
    # every leaf the CPU draws, in the same order, and only leaves the morphed-corner test drops besides
    rows = [tuple(r) for r in plain]
    at = [rows.index(tuple(r)) for r in morphed]
    assert at == sorted(at)
    extra = np.delete(plain, at, axis=0)
    vf = lod.morphed[0]
    s = vol.root >> extra[:, 0]
    for q in range(8):
        corner = extra[:, 1:] * s[:, None] + np.array([(q >> 2) & 1, (q >> 1) & 1, q & 1]) * s[:, None]
        assert np.all(vf[tuple(corner.T)] <= lod.cutoff)
    leaves = cloud_leaves(lod.update(cam, (48, 36), morph=False))
    assert leaves.n_leaves == len(plain) and len(np.unique(leaves.keys)) == len(plain)
    np.testing.assert_allclose(leaves.centre + leaves.bounds[:, 0], vol.origin)
    np.testing.assert_allclose(leaves.origin + leaves.centre, vol.origin)


@pytest.mark.parametrize("eye", EYES)
def test_refinement_thresholds_decide_as_the_octree(eye):
    """A node the octree visited is refined iff the eye is nearer its centre than its threshold (0: transparent)."""
    lod, vol = _lod(0.1)
    cam = _camera(eye, vol)
    lod.update(cam, (48, 36))
    num = lod.refinement_thresholds().astype(np.float64)
    visited = np.flatnonzero(lod._state > 0)
    assert (lod._state == 2).sum() > 5 and (lod._state == 1).sum() > 5
    for idx in visited:
        lv = int(np.searchsorted(lod.off, idx, side="right") - 1)
        dims = lod.roots << lv
        a, rem = divmod(int(idx - lod.off[lv]), int(dims[1] * dims[2]))
        b, c = divmod(rem, int(dims[2]))
        centre = np.asarray(vol.origin) + (np.array([a, b, c]) + 0.5) * (vol.root >> lv) * np.asarray(vol.spacing)
        d = np.linalg.norm(centre - cam.position)
        assert (d < num[idx]) == (lod._state[idx] == 2), (lv, a, b, c)
    assert np.all(num[lod.fmax <= lod.cutoff] == 0.0)
    lod.small_c = 2.0                              # the cache follows C and c
    assert not np.array_equal(lod.refinement_thresholds(), num.astype(np.float32))


@pytest.mark.parametrize("table_field", ["f", "gamma"])
def test_field_texels_are_the_table_field_and_the_modulation(table_field):
    shading = CloudShading.npr() if table_field == "f" else CloudShading.physical()
    _, vol = _lod(shading.cutoff)
    texels = cloud_field_texels(vol, shading)
    table, other = (vol.f, vol.gamma) if table_field == "f" else (vol.gamma, vol.f)
    assert texels.dtype == np.float32 and texels.shape == (vol.f.size, 2)
    np.testing.assert_array_equal(texels[:, 0], table.ravel())
    np.testing.assert_array_equal(texels[:, 1], (other.ravel() / modulation_scale(vol, shading)).astype(np.float32))
    i, j, k = 5, 3, 7                                                  # C order: (i ny + j) nz + k
    assert texels[(i * vol.shape[1] + j) * vol.shape[2] + k, 0] == table[i, j, k]


@pytest.mark.parametrize("scalars, rho", [
    ([0.0, 0.04, 1.0], [0.0, 0.0, 0.08]),                               # NPR: transparent below the cutoff
    ([0.0, 1.0], [0.08, 0.08]),                                         # physical: never transparent
    ([0.0, 0.2, 0.3, 0.5, 0.6, 0.8, 1.0], [0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0]),   # two bands
    (list(np.linspace(0.0, 1.0, 41)), [float(i % 2) for i in range(41)]),         # a comb: intervals joined
])
def test_visible_intervals_cull_as_visible_ranges(scalars, rho):
    tf = TransferFunction(scalars, [(1.0, 1.0, 1.0)] * len(scalars), rho)
    intervals = _visible_intervals(tf)
    assert 1 <= len(intervals) <= 8
    rng = np.random.default_rng(1)
    lo = rng.uniform(-0.1, 1.1, 4000)
    hi = lo + rng.exponential(0.05, 4000)
    shown = np.zeros(len(lo), bool)
    for a, b in intervals:
        shown |= (hi >= a) & (lo <= b)
    expected = visible_ranges(lo, hi, tf.scalars, tf.extinction)
    assert np.all(shown[expected])                                      # never drops a visible leaf
    if len(scalars) < 20:
        np.testing.assert_array_equal(shown, expected)                   # exact with few intervals
    else:
        assert shown.sum() < len(lo)
