"""Pre-integration tables against the exact reference: 3D (direct, incremental), 2D Eq. 8.2, separable Ch. 9,
isosurface textures, ZOT, incremental rebuilds, and the hard cases on every table."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.optics import (IsoSurface, TransferFunction, build_iso_table, build_separable, build_table2d,
                           build_table3d, build_zot, changed_span, heaviside_alpha, integrate_segment, iso_peaks_tf,
                           load_preset)
from volviz.optics.separable import segment_averages
from volviz.optics.tables import error_report
from volviz.optics.zot import exact_max_extinction


@pytest.fixture(scope="module")
def smooth() -> TransferFunction:
    return load_preset("viridis").scaled_extinction(3.0)


@pytest.fixture(scope="module")
def hard() -> TransferFunction:
    return TransferFunction([0.0, 0.2, 0.4, 0.5, 0.7, 1.0],
                            [[0, 0, 1], [0, 1, 1], [0, 1, 0], [1, 1, 0], [1, 0, 0], [1, 1, 1]],
                            [0.0, 0.5, 4.0, 0.2, 2.0, 1.0])


# ---- 3D table ---------------------------------------------------------------------------------------------------

def test_table3d_layout_and_exactness_at_its_sample_points(hard):
    t = build_table3d(hard, n_s=33, n_l=9, l_max=2.0)
    assert t.rgba.shape == (33, 33, 9, 4) and t.rgba.dtype == np.float32
    assert (t.s_lo, t.s_hi, t.l_max) == (0.0, 1.0, 2.0)
    i, j, k = 7, 25, 5
    ref = integrate_segment(hard, i * t.ds, j * t.ds, k * 2.0 / 8)
    np.testing.assert_allclose(t.rgba[i, j, k], ref, atol=1e-7)
    err = t.error(where="nodes")
    assert err.max_abs <= 1e-6 and err.n_samples == 33 * 33 * 9  # target: ≤ 1e-3 at its own sample points
    np.testing.assert_allclose(t.lookup(i * t.ds, j * t.ds, k * 0.25), t.rgba[i, j, k], atol=1e-7)


def test_table3d_trilinear_lookup_and_clamping(hard):
    t = build_table3d(hard, n_s=17, n_l=5, l_max=1.0)
    # midpoint in all three axes = mean of the 8 corners
    corner = t.rgba[3:5, 8:10, 1:3].astype(np.float64).mean(axis=(0, 1, 2))
    np.testing.assert_allclose(t.lookup(3.5 * t.ds, 8.5 * t.ds, 1.5 * t.dl), corner, atol=1e-12)
    np.testing.assert_allclose(t.lookup(0.3, 0.6, 5.0), t.lookup(0.3, 0.6, 1.0))  # l beyond l_max clamps
    assert np.all(t.lookup([np.nan, 0.3], [0.2, np.nan], 0.5) == 0)
    assert t.lookup(np.zeros((2, 3)), 0.5, 0.1).shape == (2, 3, 4)


def test_table3d_interpolation_error_smooth_tf(smooth):
    t = build_table3d(smooth, n_s=64, n_l=16, l_max=1.0)
    err = t.error(where="centers")
    assert err.max_abs < 0.006 and err.rms < 0.001  # measured 0.0045 / 0.0006
    report = error_report(t)
    assert set(report) == {"centers", "random"} and report["random"]["rms"] < 0.001


def test_incremental_agrees_with_direct(smooth, hard):
    for tf, bound in ((smooth, 0.003), (hard, 0.08)):  # measured 0.0022 and 0.061
        d = build_table3d(tf, n_s=64, n_l=16, l_max=1.0, method="direct")
        inc = build_table3d(tf, n_s=64, n_l=16, l_max=1.0, method="incremental")
        near = build_table3d(tf, n_s=64, n_l=16, l_max=1.0, method="incremental", m_rounding="nearest")
        np.testing.assert_array_equal(inc.rgba[:, :, :2], d.rgba[:, :, :2])  # slices 0 and 1 are direct
        diff = np.abs(inc.rgba - d.rgba).max()
        assert diff < bound
        assert np.abs(near.rgba - d.rgba).max() > diff  # VTK's nearest-index rounding is less accurate
        np.testing.assert_allclose(np.diagonal(inc.rgba, axis1=0, axis2=1), np.diagonal(d.rgba, axis1=0, axis2=1),
                                   atol=1e-6)  # m = i on the diagonal: exact composition


def test_table3d_diagonal_is_the_transfer_function(hard):
    t = build_table3d(hard, n_s=21, n_l=6, l_max=3.0)
    s = t.scalars
    rgb, rho = hard.evaluate(s)
    for k, l in enumerate(t.lengths):
        alpha = -np.expm1(-rho * l)
        diag = t.rgba[np.arange(21), np.arange(21), k]
        np.testing.assert_allclose(diag[:, 3], alpha, atol=1e-7)
        np.testing.assert_allclose(diag[:, :3], rgb * alpha[:, None], atol=1e-7)


def test_table3d_range_wider_than_tf_is_transparent_outside(hard):
    t = build_table3d(hard, n_s=31, n_l=4, l_max=1.0, s_range=(-1.0, 2.0))
    s = t.scalars
    low, high = s < 0, s > 1
    assert np.all(t.rgba[np.ix_(low, low)] == 0) and np.all(t.rgba[np.ix_(high, high)] == 0)
    assert np.all(t.rgba[np.ix_(low, high)][:, :, 1:, 3] > 0)  # crossing the whole TF range
    assert t.error(where="nodes").max_abs < 1e-6


def test_table3d_bad_arguments(hard):
    with pytest.raises(ValueError, match="method"):
        build_table3d(hard, method="magic")
    with pytest.raises(ValueError, match="n_s"):
        build_table3d(hard, n_s=1)
    with pytest.raises(ValueError, match="l_max"):
        build_table3d(hard, l_max=0.0)
    with pytest.raises(ValueError, match="s_range"):
        build_table3d(hard, s_range=(1.0, 1.0))
    with pytest.raises(ValueError, match="GiB"):
        build_table3d(hard, n_s=4096, n_l=4096)


# ---- incremental rebuild ----------------------------------------------------------------------------------------

def edited(tf: TransferFunction, index: int) -> TransferFunction:
    colors = tf.colors.copy()
    colors[index] = [1.0, 0.0, 0.0]
    rho = tf.extinction.copy()
    rho[index] *= 2.0
    return TransferFunction(tf.scalars, colors, rho, name=tf.name)


def test_changed_span():
    tf = load_preset("viridis")
    assert changed_span(tf, tf) is None
    new = edited(tf, 20)
    assert changed_span(tf, new) == (tf.scalars[19], tf.scalars[21])
    wider = TransferFunction(np.append(tf.scalars, 1.5), np.vstack([tf.colors, tf.colors[-1]]),
                             np.append(tf.extinction, tf.extinction[-1]))
    assert changed_span(tf, wider) == (1.0, 1.5)


@pytest.mark.parametrize("method", ["direct", "incremental"])
def test_table3d_partial_rebuild_equals_fresh_build(smooth, method):
    t = build_table3d(smooth, n_s=48, n_l=8, l_max=1.0, method=method)
    new = edited(smooth, 28)  # near the top of the range: only pairs reaching above s ≈ 0.84 change
    count = t.rebuild(new)
    assert 0 < count < 0.5 * 48 * 48
    fresh = build_table3d(new, n_s=48, n_l=8, l_max=1.0, method=method)
    np.testing.assert_allclose(t.rgba, fresh.rgba, atol=1e-6)
    assert t.rebuild(new) == 0  # nothing changed any more


def test_2d_and_separable_partial_rebuild(smooth):
    new = edited(smooth, 5)
    t2 = build_table2d(smooth, n_s=40, l_bar=0.5)
    assert 0 < t2.rebuild(new) < 40 * 40
    np.testing.assert_allclose(t2.lookup(*np.meshgrid(t2.scalars, t2.scalars), 0.7),
                               build_table2d(new, n_s=40, l_bar=0.5).lookup(*np.meshgrid(t2.scalars, t2.scalars),
                                                                            0.7), atol=1e-6)
    sep = build_separable(smooth, n_s=40, l_max=1.0, degree=2)
    assert 0 < sep.rebuild(new) < 40 * 40
    np.testing.assert_allclose(sep.data, build_separable(new, n_s=40, l_max=1.0, degree=2).data, atol=1e-6)


# ---- 2D table (Eq. 8.2) -----------------------------------------------------------------------------------------

def test_table2d_is_exact_at_l_bar_and_linear_in_l(hard):
    t = build_table2d(hard, n_s=65, l_bar=0.5)
    assert t.rgba.shape == (65, 65, 4) and t.rgba[..., 3].max() == pytest.approx(1.0)
    s = t.scalars
    sf, sb = np.meshgrid(s, s, indexing="ij")
    np.testing.assert_allclose(t.lookup(sf, sb, 0.5), integrate_segment(hard, sf, sb, 0.5), atol=1e-6)
    np.testing.assert_allclose(t.lookup(sf, sb, 0.25), 0.5 * t.lookup(sf, sb, 0.5), atol=1e-12)
    err = t.error(where="random", l_max=1.0)
    assert 0.005 < err.rms < 0.2  # it is an approximation, and its error is measured, not hidden


def test_table2d_large_optical_depth_never_exceeds_opacity_one(hard):
    t = build_table2d(hard.scaled_extinction(12.5), n_s=33, l_bar=0.2)
    s = np.linspace(0, 1, 33)
    for l in (0.2, 1.0, 10.0, 50.0):
        out = t.lookup(s[:, None], s[None, :], l)
        assert np.all(out[..., 3] <= 1.0) and np.all(out >= 0)
        assert np.all(out[..., :3] <= out[..., 3:] + 1e-6)  # κ ≤ 1 here


# ---- separable (Ch. 9) ------------------------------------------------------------------------------------------

def test_rho_hat_and_c0_exact(hard):
    rho_hat, c0, kmean = segment_averages(hard, [0.0, 0.2, 0.3, 0.3, 1.5, np.nan], [0.2, 0.0, 0.3, 0.5, 2.0, 0.1])
    np.testing.assert_allclose(rho_hat[:3], [0.25, 0.25, 2.25])
    np.testing.assert_allclose(rho_hat[3], (0.5 * 0.1 * (2.25 + 4.0) + 0.5 * 0.1 * (4.0 + 0.2)) / 0.2)
    assert rho_hat[4] == 0 and rho_hat[5] == 0 and np.all(c0[4:] == 0)
    # Ĉ_0 = ∫κρ/∫ρ on [0, 0.2]: κ = (0, 5s, 1), ρ = 2.5 s → ∫κ_g ρ / ∫ρ = (5·2.5/3 · 0.008)/(2.5/2 · 0.04) = 2/3
    np.testing.assert_allclose(c0[0], [0, 2 / 3, 1], atol=1e-14)
    np.testing.assert_allclose(kmean[0], [0, 0.5, 1], atol=1e-14)


def test_separable_opacity_exact_and_color_converges_with_degree(smooth):
    errs = {}
    for degree in (1, 2, 4):
        t = build_separable(smooth, n_s=64, l_max=1.0, degree=degree)
        s = t.scalars
        sf, sb = np.meshgrid(s, s, indexing="ij")
        for l in (0.3, 1.0, 4.0):  # α = 1 − exp(−l ρ̂) is exact at the nodes for any l
            np.testing.assert_allclose(t.lookup(sf, sb, l)[..., 3], integrate_segment(smooth, sf, sb, l)[..., 3],
                                       atol=2e-7)
        # the color polynomial interpolates the samples l = (i/n)·l_max
        for i in range(1, degree + 1):
            l = i / degree
            np.testing.assert_allclose(t.lookup(sf, sb, l), integrate_segment(smooth, sf, sb, l), atol=2e-6)
        errs[degree] = t.error(where="centers")
    assert errs[1].rms > errs[2].rms > errs[4].rms
    assert errs[2].max_abs < 0.002  # measured 0.0015 (dominated by the bilinear ρ̂ and C̃ interpolation)


def test_separable_zero_density_and_limits_are_finite():
    tf = TransferFunction([0, 0.5, 0.6, 1], [[0.2, 0.4, 0.6], [1, 1, 1], [1, 0, 0], [0, 1, 0]], [0, 0, 50, 1e6])
    t = build_separable(tf, n_s=41, l_max=1.0, degree=4)
    assert np.all(np.isfinite(t.data))
    s = np.linspace(-0.5, 1.5, 61)
    for l in (0.0, 1e-12, 0.5, 1.0, 30.0):
        out = t.lookup(s[:, None], s[None, :], l)
        assert np.all(np.isfinite(out)) and np.all(out >= 0) and np.all(out[..., 3] <= 1)
        assert np.all(out[..., :3] <= out[..., 3:] * 1.0 + 1e-6)  # no polynomial overshoot beyond κ_max
    assert np.all(t.lookup(s, s, 0.0) == 0)  # l = 0
    zero = t.lookup(0.1, 0.4, 1.0)  # ∫ρ = 0 segment
    assert np.all(zero == 0)
    # where ∫ρ = 0 the chromaticity is the mean κ (constant polynomial)
    i, j = 4, 16  # s = 0.1, 0.4
    np.testing.assert_allclose(t.coefficients[i, j, 0], tf.evaluate(0.25)[0], atol=1e-6)
    np.testing.assert_allclose(t.coefficients[i, j, 1:], 0, atol=1e-12)


# ---- isosurfaces (§8.8–8.13) ------------------------------------------------------------------------------------

def test_heaviside_conventions():
    out = heaviside_alpha([0.1, 0.4, 0.3, 0.3, 0.2, 0.3, np.nan], [0.4, 0.1, 0.4, 0.2, 0.25, 0.3, 0.5], 0.3)
    np.testing.assert_array_equal(out, [1, 1, 0.5, 0.5, 0, 0, 0])
    assert heaviside_alpha(0.31, 0.31, 0.3, thicken=0.02) == 1.0


def test_thin_peak_tf_converges_to_the_heaviside_limit():
    """§8.13: ρ = C δ(s − s_iso) gives α = H·H independent of l as C → ∞."""
    s = np.linspace(0, 1, 41) + 0.0123  # avoid grid points exactly on the isovalue
    sf, sb = np.meshgrid(s, s, indexing="ij")
    limit = heaviside_alpha(sf, sb, 0.5)
    prev = None
    for area in (1.0, 10.0, 100.0):
        tf = iso_peaks_tf([0.5], width=1e-4, area=area)
        for l in (0.1, 1.0):
            err = np.abs(integrate_segment(tf, sf, sb, l)[..., 3] - limit).max()
            if l == 1.0:
                assert prev is None or err < prev
                prev = err
    assert prev < 1e-12  # crossing segments have depth area·l/|Δs| ≥ 100 here, others exactly 0


def test_iso_texture_multiple_colored_surfaces_and_weights():
    isos = [IsoSurface(0.3, (1, 0, 0)), IsoSurface(0.6, (0, 1, 0), opacity=0.5, back_color=(0, 0, 1))]
    t = build_iso_table(isos, n_s=101, s_range=(0, 1))
    np.testing.assert_allclose(t.lookup(0.1, 0.5), [1, 0, 0, 1], atol=1e-6)  # increasing: red first, opaque
    np.testing.assert_allclose(t.lookup(0.5, 0.8), [0, 0.5, 0, 0.5], atol=1e-6)  # green, half transparent
    np.testing.assert_allclose(t.lookup(0.9, 0.1), [0.5, 0, 0.5, 1], atol=1e-6)  # decreasing: blue side, then red
    np.testing.assert_allclose(t.lookup(0.7, 0.7), 0, atol=0)  # diagonal: no crossing
    assert t.lookup_weight(0.2, 0.4) == pytest.approx(0.5)  # (s_iso − s_b)/(s_f − s_b)
    assert t.lookup_weight(0.25, 0.45) == pytest.approx(0.75)
    assert t.lookup_weight(0.5, 0.5) == 0
    np.testing.assert_allclose(t.smooth_front_rgba()[20, 40], [0.5, 0, 0, 0.5], atol=1e-6)
    assert np.all(np.isfinite(t.rgba)) and np.all(np.isfinite(t.front_weight))


def test_flat_iso_texture_equals_the_3d_table_limit_at_nodes():
    isos = [IsoSurface(0.305, (1, 0.5, 0)), IsoSurface(0.705, (0, 0.5, 1))]
    t = build_iso_table(isos, n_s=51, s_range=(0, 1))
    err = t.error(area=1e4, where="nodes")
    assert err.max_abs < 1e-6
    thick = build_iso_table([0.5], n_s=51, s_range=(0, 1), thicken=0.03)
    assert thick.lookup(0.52, 0.52)[3] == 1.0 and thick.lookup(0.6, 0.6)[3] == 0.0


# ---- ZOT --------------------------------------------------------------------------------------------------------

def test_zot_is_conservative_for_a_thin_peak():
    tf = TransferFunction([0, 0.4, 0.40005, 0.4001, 0.8, 0.9, 1], [[1, 1, 1]] * 7, [0, 0, 7, 0, 0, 1, 0])
    z = build_zot(tf, n_bins=64)
    rep = error_report(z)
    assert rep["false_transparent"] == 0 and rep["underestimates"] == 0 and rep["false_visible"] < 0.05
    assert not z.is_transparent(0.40004, 0.40006)  # interval far inside one bin, only the peak
    assert z.is_transparent(0.1, 0.3) and z.is_transparent(0.5, 0.75)
    assert z.is_transparent(-2, -1) and z.is_transparent(np.nan, 0.5)
    assert not z.is_transparent(0.3, 0.95)
    np.testing.assert_allclose(exact_max_extinction(tf, [0.0, 0.85, 0.95], [1.0, 0.95, 0.92]), [7, 1, 0.8])
    assert z.opacity_bound(0.3, 0.95, 2.0) == pytest.approx(1 - np.exp(-14))


# ---- all-zero opacity and huge ρ on every table ------------------------------------------------------------------

def test_all_tables_with_zero_opacity_and_with_rho_1e6():
    zero = TransferFunction([0, 1], [[1, 1, 1]] * 2, [0, 0])
    dense = TransferFunction([0, 0.5, 1], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [1e6, 0, 1e6])
    s = np.linspace(-0.2, 1.2, 15)
    for tf in (zero, dense):
        tables = [build_table3d(tf, 17, 5, 1.0), build_table3d(tf, 17, 5, 1.0, "incremental"),
                  build_table2d(tf, 17, 0.5), build_separable(tf, 17, 1.0, 2)]
        for t in tables:
            out = t.lookup(s[:, None], s[None, :], 0.7)
            assert np.all(np.isfinite(out)) and np.all(out >= 0) and np.all(out[..., 3] <= 1)
            if tf is zero:
                assert np.all(out == 0)
        z = build_zot(tf, 16)
        assert np.all(z.is_transparent(s, s)) == (tf is zero)


def test_table3d_job_reports_progress_and_cancels(hard):
    from volviz.optics.tables import build_table3d_job

    for method in ("direct", "incremental"):
        seen: list[float] = []
        table = build_table3d_job(hard, n_s=200, n_l=40, l_max=1.0, method=method,
                                  progress=lambda f, msg: seen.append(f))
        assert len(seen) >= 2 and seen == sorted(seen) and seen[-1] == 1.0
        np.testing.assert_allclose(table.rgba, build_table3d(hard, 200, 40, 1.0, method).rgba, atol=0)

    class Stop(Exception):
        pass

    def stop(fraction: float, message: str) -> None:
        raise Stop(message)

    with pytest.raises(Stop, match="pre-integration"):
        build_table3d_job(hard, n_s=200, n_l=40, progress=stop)


def test_nan_and_negative_inputs_to_every_lookup_are_transparent(hard):
    tables = [build_table3d(hard, 9, 4, 1.0), build_table2d(hard, 9, 0.5), build_separable(hard, 9, 1.0, 2),
              build_iso_table([0.5], 9)]
    for t in tables:
        out = t.lookup([np.nan, 0.2, 0.2, 0.2], [0.8, np.nan, 0.8, 0.8], [0.5, 0.5, np.nan, -1.0])
        assert np.all(np.isfinite(out))
        if not hasattr(t, "isosurfaces"):  # iso textures ignore l
            assert np.all(out == 0)
