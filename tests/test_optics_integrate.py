"""The exact segment integral (Roettger Eq. 8.1): closed forms, 10^6-step Riemann sums, and every hard case."""
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.special as sp
from scipy.integrate import quad

from volviz.optics import TransferFunction, integrate_segment
from volviz.optics.integrate import dawson, erfcx, mean_transmittance, riemann_segment

TOL = 1e-9


def rainbow_tf() -> TransferFunction:
    return TransferFunction(
        [0.0, 0.2, 0.4, 0.5, 0.7, 1.0],
        [[0, 0, 1], [0, 1, 1], [0, 1, 0], [1, 1, 0], [1, 0, 0], [1, 1, 1]],
        [0.0, 0.5, 4.0, 0.2, 2.0, 1.0],
    )


def test_special_functions_match_scipy():
    x = np.concatenate([np.linspace(0, 40, 4001), np.geomspace(1e-10, 1e12, 500)])
    np.testing.assert_allclose(erfcx(x), sp.erfcx(x), rtol=2e-14, atol=0)
    np.testing.assert_allclose(dawson(x), sp.dawsn(x), rtol=2e-14, atol=1e-300)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_mean_transmittance_matches_adaptive_quadrature_over_a_wide_grid():
    dens = np.concatenate([[0.0], np.geomspace(1e-6, 1e6, 25)])
    ra, rb = np.meshgrid(dens, dens)
    p, q = ra.ravel(), 0.5 * (rb - ra).ravel()
    m = mean_transmittance(p, q)
    worst = 0.0
    edges = np.concatenate([[0.0], np.geomspace(1e-9, 1.0, 40)])
    for pi, qi, mi in zip(p, q, m):
        ref = sum(quad(lambda x: np.exp(-pi * x - qi * x * x), a, b, epsabs=1e-17, epsrel=1e-14)[0]
                  for a, b in zip(edges[:-1], edges[1:]))
        worst = max(worst, abs(ref - mi))
    assert worst < 1e-13


@pytest.mark.parametrize("s_f, s_b, length", [(0.0, 1.0, 1.0), (1.0, 0.0, 1.0), (0.15, 0.85, 3.0),
                                               (0.9, 0.1, 0.5), (-0.5, 1.5, 2.0), (0.45, 0.46, 4.0)])
def test_matches_riemann_sum_with_a_million_steps(s_f, s_b, length):
    tf = rainbow_tf()
    exact = integrate_segment(tf, s_f, s_b, length)
    brute = riemann_segment(tf, s_f, s_b, length, steps=1_000_000)
    np.testing.assert_allclose(exact, brute, atol=TOL, rtol=0)


def test_constant_scalar_closed_form():
    tf = rainbow_tf()
    s = np.linspace(-0.2, 1.2, 57)
    for length in (0.0, 1e-9, 0.3, 7.0, 1e4):
        rgb, rho = tf.evaluate(s)
        alpha = -np.expm1(-rho * length)
        got = integrate_segment(tf, s, s, length)
        np.testing.assert_allclose(got[:, 3], alpha, atol=1e-15)
        np.testing.assert_allclose(got[:, :3], rgb * alpha[:, None], atol=1e-15)


@pytest.mark.parametrize("rho", [1e-8, 0.3, 5.0, 50.0, 1e6])
def test_constant_rho_with_linear_color_closed_form(rho):
    tf = TransferFunction([0.0, 1.0], [[0.2, 0.9, 0.0], [1.0, 0.1, 0.5]], [rho, rho])
    k0, k1 = tf.colors
    for s_f, s_b, length in [(0.0, 1.0, 1.0), (1.0, 0.0, 2.0), (0.3, 0.6, 0.01)]:
        ka, kb = tf.evaluate(s_f)[0], tf.evaluate(s_b)[0]
        x = rho * length
        e = np.exp(-x)
        # ∫_0^l t ρ e^{-ρt} dt = g(x)/ρ with g(x) = 1 − e^{-x}(1 + x); series for small x (no cancellation)
        if x < 1.0:
            g = sum((-1) ** k * x ** k * (k - 1) / math.factorial(k) for k in range(2, 30))
        else:
            g = 1.0 - e * (1.0 + x)
        t_moment = g / rho
        color = ka * (1 - e) + (kb - ka) / length * t_moment
        got = integrate_segment(tf, s_f, s_b, length)
        np.testing.assert_allclose(got[:3], color, atol=1e-12)
        assert got[3] == pytest.approx(-np.expm1(-rho * length), abs=1e-15)


def test_broadcasting_and_shapes():
    tf = rainbow_tf()
    s = np.linspace(0, 1, 5)
    out = integrate_segment(tf, s[:, None, None], s[None, :, None], np.array([0.5, 1.0])[None, None, :])
    assert out.shape == (5, 5, 2, 4) and out.dtype == np.float64
    np.testing.assert_array_equal(out[2, 3, 1], integrate_segment(tf, s[2], s[3], 1.0))
    assert integrate_segment(tf, 0.1, 0.2, 1.0).shape == (4,)
    assert integrate_segment(tf, [], [], 1.0).shape == (0, 4)


# ---- hard cases (Roettger digest §15.2) -------------------------------------------------------------------------

def test_zero_length_is_exactly_zero():
    tf = rainbow_tf()
    s = np.linspace(-1, 2, 31)
    assert np.all(integrate_segment(tf, s[:, None], s[None, :], 0.0) == 0.0)


def test_zero_extinction_segments_are_zero_not_nan():
    tf = TransferFunction([0, 0.3, 0.6, 1], [[1, 1, 1]] * 4, [0, 0, 5, 5])
    out = integrate_segment(tf, [0.0, 0.3, 0.1, 0.25], [0.3, 0.0, 0.1, 0.05], 10.0)
    assert np.all(out == 0.0)


def test_large_optical_depth_has_no_negative_transmittance_or_overshoot():
    tf = rainbow_tf().scaled_extinction(12.5)  # ρ up to 50 per unit length
    s = np.linspace(0, 1, 41)
    for length in (1.0, 5.0, 100.0):
        out = integrate_segment(tf, s[:, None], s[None, :], length)
        assert np.all(out[..., 3] >= 0) and np.all(out[..., 3] <= 1)
        assert np.all(out[..., :3] >= 0) and np.all(out[..., :3] <= out[..., 3:] * 1.0 + 1e-15)
    # optical depth 50 exactly: constant ρ = 50, l = 1
    tf50 = TransferFunction([0, 1], [[1, 0.5, 0.25]] * 2, [50, 50])
    out = integrate_segment(tf50, 0.2, 0.8, 1.0)
    np.testing.assert_allclose(out, [*(np.array([1, 0.5, 0.25]) * -np.expm1(-50.0)), -np.expm1(-50.0)], atol=1e-15)


def test_step_transfer_function_closed_form():
    # ρ jumps from 0 to 3 at s = 0.5 (over 1e-12), color constant: α = 1 − exp(−3 · l · fraction above 0.5)
    step = TransferFunction([0.0, 0.5, 0.5 + 1e-12, 1.0], [[0.2, 0.4, 0.8]] * 4, [0.0, 0.0, 3.0, 3.0])
    for s_f, s_b, length in [(0.0, 1.0, 1.0), (1.0, 0.0, 2.0), (0.25, 0.75, 4.0), (0.4, 0.9, 0.5)]:
        frac = (max(s_f, s_b) - 0.5) / abs(s_b - s_f)
        alpha = -np.expm1(-3.0 * length * frac)
        np.testing.assert_allclose(integrate_segment(step, s_f, s_b, length),
                                   [0.2 * alpha, 0.4 * alpha, 0.8 * alpha, alpha], atol=1e-10)


def test_thin_peak_of_1e4_of_the_range():
    width, height = 1e-4, 2e4  # area 1.0 in scalar units
    tf = TransferFunction([0, 0.5 - width / 2, 0.5, 0.5 + width / 2, 1], [[1, 0.5, 0]] * 5,
                          [0, 0, height, 0, 0])
    for s_f, s_b, length in [(0.0, 1.0, 1.0), (0.9, 0.2, 0.35), (0.49, 0.51, 0.01)]:
        depth = 1.0 * length / abs(s_b - s_f)  # ∫ρ dt = area · l / |Δs|
        alpha = -np.expm1(-depth)
        np.testing.assert_allclose(integrate_segment(tf, s_f, s_b, length), [alpha, 0.5 * alpha, 0, alpha],
                                   atol=1e-12)
    brute = riemann_segment(tf, 0.0, 1.0, 1.0, steps=1_000_000)  # 100 samples inside the peak
    np.testing.assert_allclose(integrate_segment(tf, 0.0, 1.0, 1.0), brute, atol=1e-7)
    assert np.all(integrate_segment(tf, [0.0, 0.6], [0.4999, 1.0], 5.0) == 0)  # misses the peak entirely


def test_scalars_outside_the_range_are_transparent():
    tf = rainbow_tf()
    # [-1, 2] over l = 3: the part inside [0, 1] is the sub-segment 0 → 1 of length 1, with nothing in front
    np.testing.assert_allclose(integrate_segment(tf, -1.0, 2.0, 3.0), integrate_segment(tf, 0.0, 1.0, 1.0),
                               atol=1e-14)
    np.testing.assert_allclose(integrate_segment(tf, 2.0, -1.0, 3.0), integrate_segment(tf, 1.0, 0.0, 1.0),
                               atol=1e-14)
    assert np.all(integrate_segment(tf, [-3.0, 1.5, -1.0], [-0.5, 9.0, -1.0], 2.0) == 0)


def test_nan_scalars_are_transparent():
    tf = rainbow_tf()
    out = integrate_segment(tf, [np.nan, 0.5, np.nan], [0.5, np.nan, np.nan], 1.0)
    assert np.all(out == 0.0)


def test_all_zero_opacity_is_all_zero():
    tf = TransferFunction([0, 1], [[1, 1, 1]] * 2, [0, 0])
    s = np.linspace(-0.5, 1.5, 21)
    assert np.all(integrate_segment(tf, s[:, None], s[None, :], 3.0) == 0.0)


def test_rho_up_to_a_million():
    tf = TransferFunction([0, 1], [[0.0, 1.0, 0.5], [1.0, 0.0, 0.5]], [1e6, 1e6])
    out = integrate_segment(tf, 0.0, 1.0, 1.0)
    # color ≈ front color + (κ_b − κ_a)/(ρ l): only the first 1e-6 of the segment is seen
    np.testing.assert_allclose(out, [1e-6, 1 - 1e-6, 0.5, 1.0], atol=1e-15)
    ramp = TransferFunction([0, 1], [[1, 1, 1]] * 2, [0, 1e6])
    out = integrate_segment(ramp, [0.0, 1.0, 0.0], [1.0, 0.0, 1e-9], [1.0, 1.0, 1e-3])
    # ramp from 0: depth at t is 1e6 t²/2 → color = α = 1; ramp reversed: α = 1; tiny segment: depth 5e-10
    np.testing.assert_allclose(out[0], [1, 1, 1, 1], atol=1e-15)
    np.testing.assert_allclose(out[1], [1, 1, 1, 1], atol=1e-15)
    assert out[2, 3] == pytest.approx(-np.expm1(-1e6 * 0.5e-9 * 1e-3), rel=1e-9)


def test_random_extreme_inputs_never_produce_nan_or_inf():
    rng = np.random.default_rng(7)
    for _ in range(20):
        n = rng.integers(2, 9)
        s = np.sort(rng.uniform(-10, 10, n))
        s += np.arange(n) * 1e-9  # strictly increasing
        rho = rng.choice([0.0, 1e-12, 0.5, 50.0, 1e6], n)
        col = rng.uniform(0, 1, (n, 3))
        tf = TransferFunction(s, col, rho)
        m = 2000
        sf = rng.uniform(-12, 12, m)
        sb = np.where(rng.random(m) < 0.2, sf, rng.uniform(-12, 12, m))
        sf[rng.random(m) < 0.05] = np.nan
        length = rng.choice([0.0, 1e-12, 1e-3, 1.0, 1e3], m)
        out = integrate_segment(tf, sf, sb, length)
        assert np.all(np.isfinite(out))
        assert np.all(out[:, 3] >= 0) and np.all(out[:, 3] <= 1)
        assert np.all(out[:, :3] >= 0) and np.all(out[:, :3] <= out[:, 3:] * col.max() + 1e-12)


def test_bad_lengths_raise():
    tf = rainbow_tf()
    for bad in (-1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="length"):
            integrate_segment(tf, 0.0, 1.0, bad)
    with pytest.raises(ValueError, match="infinite"):
        integrate_segment(tf, -np.inf, 1.0, 1.0)
    with pytest.raises(TypeError):
        integrate_segment("not a tf", 0.0, 1.0, 1.0)
