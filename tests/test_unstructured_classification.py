"""Pre- versus post-classification (Roettger §8.14): the pre-classified segment integral against closed forms, the
pre-classified 3D table, and method "pt" against "reference" under either classification."""
from __future__ import annotations

import math

import numpy as np
import pytest

from volviz.optics import TransferFunction, build_table3d, integrate_preclassified, integrate_segment
from volviz.unstructured import synthetic as syn
from volviz.model.camera import Camera
from volviz.unstructured.render import render

#: a thin opacity peak at 0.5 between two transparent ends: what pre-classification loses
PEAK = TransferFunction([0.0, 0.45, 0.5, 0.55, 1.0], [[1, 1, 1], [1, 0.2, 0.1], [1, 0.2, 0.1], [1, 0.2, 0.1], [1, 1, 1]],
                        [0.0, 0.0, 12.0, 0.0, 0.0])


def test_preclassified_equals_post_where_tf_is_linear():
    tf = TransferFunction([0.0, 1.0], [[0.1, 0.5, 0.9], [0.8, 0.3, 0.2]], [0.5, 3.0])
    rng = np.random.default_rng(1)
    sf, sb, ln = rng.random(500), rng.random(500), rng.random(500) * 2.0
    assert np.abs(integrate_preclassified(tf, sf, sb, ln) - integrate_segment(tf, sf, sb, ln)).max() < 1e-12


def test_preclassified_closed_forms():
    # both ends transparent: the peak in between is lost entirely
    assert np.array_equal(integrate_preclassified(PEAK, 0.2, 0.8, 1.0), np.zeros(4))
    # post-classification sees the whole peak: optical depth = integral of rho over the segment = 12 * 0.05 * l
    post = integrate_segment(PEAK, 0.2, 0.8, 1.0)
    assert post[3] == pytest.approx(1.0 - math.exp(-12 * 0.05 / 0.6), rel=1e-9)
    # constant ends: alpha = 1 - exp(-l rho), color = kappa alpha
    tf = TransferFunction([0.0, 1.0], [[0.2, 0.4, 0.6], [0.2, 0.4, 0.6]], [2.0, 2.0])
    got = integrate_preclassified(tf, 0.3, 0.3, 0.7)
    a = 1.0 - math.exp(-1.4)
    assert got == pytest.approx([0.2 * a, 0.4 * a, 0.6 * a, a], abs=1e-12)
    # NaN or out-of-range ends are transparent, zero length gives zero
    assert np.array_equal(integrate_preclassified(tf, np.nan, np.nan, 1.0), np.zeros(4))
    assert np.array_equal(integrate_preclassified(tf, 0.5, 0.5, 0.0), np.zeros(4))


def test_preclassified_table_matches_its_integral():
    table = build_table3d(PEAK, n_s=64, n_l=32, l_max=1.0, classification="pre")
    assert table.classification == "pre"
    err = table.error(where="nodes")
    assert err.max_abs < 1e-6
    with pytest.raises(ValueError, match="direct"):
        build_table3d(PEAK, n_s=16, n_l=8, classification="pre", method="incremental")
    with pytest.raises(ValueError, match="classification"):
        build_table3d(PEAK, n_s=16, n_l=8, classification="maybe")


@pytest.mark.parametrize("classification", ["pre", "post"])
def test_pt_matches_reference_under_each_classification(classification):
    m = syn.box_tets(4, jitter=0.2, seed=2)
    cam = Camera.orbit(m.points, 30, 25, 2.2)
    ref = render(m, PEAK, cam, (40, 32), "reference", classification=classification)
    img = render(m, PEAK, cam, (40, 32), "pt", classification=classification)
    d = (img - ref) * 255.0
    assert ref[..., 3].max() > 0.05
    assert float(np.sqrt((d ** 2).mean())) <= 1.0 and float(np.abs(d).max()) <= 4.0


def test_pre_classification_loses_a_peak_inside_cells():
    # scalar = x on a 4^3 grid seen along x: every ray crosses the peak at x = 0.5 inside the middle layer of cubes
    # (faces at x = 1/3 and 2/3, where the TF is transparent). Post-classification draws the slab everywhere:
    # optical depth = integral of rho dx = 12 x 0.05 (the peak's area). Pre-classification only sees the peak where
    # a segment happens to end near x = 0.5 on an inner face of the 5-tetrahedra split: from nothing to too much,
    # depending on where the inner faces cut each ray (measured: alpha 0 to 0.79, RMS deviation 0.25).
    m = syn.box_tets(4, field=lambda p: p[..., 0])
    cam = Camera((5.0, 0.52, 0.47), (0.5, 0.5, 0.5), (0, 0, 1), parallel=True, parallel_scale=0.3,
                 clipping_range=(0.1, 10.0))
    post = render(m, PEAK, cam, (24, 24), "pt")
    pre = render(m, PEAK, cam, (24, 24), "pt", classification="pre")
    assert float(np.sqrt(((pre[..., 3] - (1.0 - math.exp(-0.6))) ** 2).mean())) > 0.15
    assert pre[..., 3].min() < 0.01 and pre[..., 3].max() > 0.6
    assert post[..., 3] == pytest.approx(np.full((24, 24), 1.0 - math.exp(-0.6)), abs=2e-3)
    with pytest.raises(ValueError, match="classification"):
        render(m, PEAK, cam, (8, 8), "pt", classification="vertex")
