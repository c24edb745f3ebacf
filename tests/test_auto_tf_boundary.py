"""The automatic transfer function's opacity at the boundaries between materials (volviz.optics.boundary, after
Kindlmann & Durkin 1998): made volumes whose boundaries lie at known values."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ndtr

from volviz.optics.auto_tf import TARGET_DEPTH, auto_transfer_function, robust_range
from volviz.optics.boundary import BINS, boundary_profile, boundary_transfer_function, derivatives, regular_fields


def _shells() -> np.ndarray:
    """48³ samples: background 0 outside radius 20 (51 % of them), a shell of material 100 and a core of material
    200 inside radius 12, each step blurred by a Gaussian of 1.5 samples; and a long tail: a small spike up to 2000
    in a corner (0.1 % of the samples)."""
    n = 48
    i, j, k = np.meshgrid(*[np.arange(n, dtype=np.float64)] * 3, indexing="ij")
    r = np.sqrt((i - 23.5) ** 2 + (j - 23.5) ** 2 + (k - 23.5) ** 2)
    spike = np.sqrt((i - 4) ** 2 + (j - 4) ** 2 + (k - 4) ** 2)
    return 100 * ndtr((20 - r) / 1.5) + 100 * ndtr((12 - r) / 1.5) + 2000 * np.exp(-spike / 1.5) * (spike < 4)


def test_a_blurred_step_gives_its_blur_and_the_signed_distance():
    """A planar step of 100 blurred by σ = 1 (2 samples at spacing 0.5): the model's σ = g_max / (√e h_max) comes
    back within 15 % (central differences), and p(v) is negative below the middle value 50, positive above, and
    antisymmetric about it."""
    x = (np.arange(64) - 31.5) * 0.5
    field = np.broadcast_to(100 * ndtr(x)[:, None, None], (64, 16, 16)).copy()
    profile = boundary_profile([field], (0.5, 0.5, 0.5), 0.0, 100.0, 20)
    assert profile.sigma == pytest.approx(1.0, rel=0.15)
    shown = np.isfinite(profile.position)
    centres, p = profile.centres[shown], profile.position[shown]
    assert np.all(p[centres < 50] < 0) and np.all(p[centres > 50] > 0)
    np.testing.assert_allclose(p, -p[::-1], rtol=1e-5)                # float32 derivatives
    assert np.all(np.diff(p) > 0)                                 # farther from the middle, farther from the boundary


def test_opacity_sits_at_the_boundary_values_not_the_materials():
    """Two boundaries (0 | 100 at radius 20, 100 | 200 at radius 12): the extinction's two maxima lie in the bins
    that hold 50 and 150, the bins of the materials 100 and 200 are transparent, and so is the background 0; the
    spike's long tail does not stretch the range (robust percentiles)."""
    field = _shells()
    lo, hi = robust_range(field.ravel())
    assert hi == pytest.approx(200.0, abs=0.01)
    width = (hi - lo) / BINS
    bin_of = lambda v: int((v - lo) // width)
    emphasis = boundary_profile([field], (1.0, 1.0, 1.0), lo, hi, BINS).emphasis()
    lower, upper = emphasis[:bin_of(100.0)], emphasis[bin_of(100.0):]
    assert int(np.argmax(lower)) == bin_of(50.0) == 6
    assert bin_of(100.0) + int(np.argmax(upper)) == bin_of(150.0) == 23
    assert emphasis[bin_of(100.0)] == 0.0 and emphasis[bin_of(200.0) - 1] == 0.0
    tf = boundary_transfer_function(field, 40.0, ([field], (1.0, 1.0, 1.0)))
    rho = tf.evaluate(np.array([0.0, 50.0, 100.0, 150.0, 200.0]))[1]
    assert rho[0] == 0.0 and rho[2] == 0.0 and rho[4] == 0.0
    assert rho[1] > 0.8 * tf.max_extinction and rho[3] > 0.8 * tf.max_extinction
    assert float(np.mean(tf.evaluate(field.ravel())[1])) * 40.0 == pytest.approx(TARGET_DEPTH, rel=0.02)
    ramp = auto_transfer_function(field, chord=40.0)              # the histogram alone: the core is the most opaque
    assert ramp.evaluate(np.array([200.0]))[1][0] == ramp.max_extinction


def test_the_boundary_rule_keeps_the_other_views():
    """Signed data keeps the diverging view, and a grid without a boundary in the range (a constant field) none;
    a subsample of a large grid keeps every k-th sample along each axis at k times the spacing."""
    rng = np.random.default_rng(7)
    signed = rng.laplace(0.0, 100.0, (40, 40, 40))
    grid = ([signed], (1.0, 1.0, 1.0))
    assert boundary_transfer_function(signed, 4.0, grid, "auto") == auto_transfer_function(signed, 4.0)
    flat = np.full((8, 8, 8), 3.0)
    assert boundary_profile([flat], (1.0, 1.0, 1.0), 0.0, 5.0) is None
    ramp = np.broadcast_to(np.arange(160.0)[:, None, None], (160, 120, 120))     # 2.3 M samples
    values, g, h = derivatives(ramp, (0.5, 1.0, 1.0))
    assert values.size == 80 * 60 * 60                            # k = 2
    np.testing.assert_allclose(g, 2.0)                            # slope 1 per 0.5: 2 per unit, whatever the step
    np.testing.assert_allclose(h, 0.0, atol=1e-9)


def test_regular_fields_of_a_volume_and_a_series():
    from volviz.model.datasets import RegularVolume, TimeSeries

    volume = RegularVolume(np.arange(27.0).reshape(3, 3, 3), spacing=(1.0, 2.0, 3.0))
    fields, spacing = regular_fields(volume)
    assert len(fields) == 1 and fields[0] is volume.data and spacing == (1.0, 2.0, 3.0)
    series = TimeSeries(np.arange(10.0), [RegularVolume(np.full((3, 3, 3), float(t))) for t in range(10)])
    fields, _ = regular_fields(series)
    assert [float(f[0, 0, 0]) for f in fields] == [0.0, 3.0, 6.0, 9.0]
