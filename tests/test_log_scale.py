"""The log color scale (``volviz.optics.log_scale``) and the edited scalar bar (render option
``scalar_bar_style``): issue #28's missing tools, without a window."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.settings import SettingsError, validate_render_options, validate_settings
from volviz.optics import TransferFunction
from volviz.optics.log_scale import log_mapped, log_ticks, positive_floor


def _tf() -> TransferFunction:
    return TransferFunction([0.0, 10.0, 100.0], [[0, 0, 1], [0, 1, 0], [1, 0, 0]], [0.0, 2.0, 4.0])


def test_log_mapping_interpolates_in_log10_and_clamps_at_the_floor():
    tf = log_mapped(_tf(), 1.0)
    assert tf.range == (0.0, 100.0)
    colors, extinction = tf.evaluate(np.array([1.0, 10.0, 100.0]))
    # log10(1) = 0 is below the first positive knot: the color of the floor (the knot at 0 clamped to 1 is the 0's)
    np.testing.assert_allclose(colors[1:], [[0, 1, 0], [1, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(extinction[1:], [2.0, 4.0], atol=1e-12)
    # halfway in log10 between 10 and 100 (31.6) is halfway in color; linear mapping would give 0.24 there
    c, e = tf.evaluate(np.array([10 ** 1.5]))
    np.testing.assert_allclose(c[0], [0.5, 0.5, 0.0], atol=5e-3)
    np.testing.assert_allclose(e, [3.0], atol=1e-2)
    # values at or below 0 take the floor's color and opacity
    c0, e0 = tf.evaluate(np.array([0.0, 0.5]))
    c1, e1 = tf.evaluate(np.array([1.0]))
    np.testing.assert_allclose(c0, np.vstack([c1, c1]), atol=1e-12)
    np.testing.assert_allclose(e0, [e1[0], e1[0]], atol=1e-12)


def test_a_range_without_positive_values_is_left_linear():
    tf = TransferFunction([-5.0, -1.0], [[0, 0, 0], [1, 1, 1]], [0.0, 1.0])
    assert log_mapped(tf, positive_floor(np.array([-5.0, -1.0]), -5.0, -1.0)) == tf


def test_positive_floor_is_the_smallest_positive_value():
    assert positive_floor(np.array([0, 0, 3, 7, 250], dtype=np.uint8), 0.0, 250.0) == 3.0
    assert positive_floor(np.array([-1.0, np.nan, 0.02, 5.0]), -1.0, 5.0) == 0.02
    assert positive_floor(np.array([0.0]), 2.5, 9.0) == 2.5


def test_log_ticks_are_decades_with_the_ends():
    np.testing.assert_allclose(log_ticks(0.01, 1e4), [0.01, 0.1, 1, 10, 100, 1000, 1e4])
    np.testing.assert_allclose(log_ticks(1.0, 1000.0), [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000])
    np.testing.assert_allclose(log_ticks(1.0, 255.0), [1, 2, 5, 10, 20, 50, 100, 255])
    np.testing.assert_allclose(log_ticks(3.0, 9.0), [3, 5, 9])   # less than a decade: 1-2-3-5 steps


def test_log_scale_is_a_volume_setting():
    assert validate_settings("volume", {"log_scale": True}) == {"log_scale": True}
    with pytest.raises(SettingsError, match="log_scale"):
        validate_settings("volume", {"log_scale": [1]})


@pytest.mark.parametrize("style", [{"title": "Density", "range": [1.0, 200.0], "format": "%.3g"},
                                   {"format": "%-#6.2e K"}, {}])
def test_scalar_bar_styles_are_render_options(style):
    assert validate_render_options({"scalar_bar_style": style}).scalar_bar_style.model_dump(exclude_unset=True) \
        == {k: tuple(v) if isinstance(v, list) else v for k, v in style.items()}


@pytest.mark.parametrize("style, message", [({"format": "%s"}, "format"), ({"format": "%d%n"}, "format"),
                                            ({"format": "%.3g %g"}, "format"), ({"range": [5, 1]}, "range"),
                                            ({"color": 1}, "unknown setting")])
def test_bad_scalar_bar_styles_are_refused(style, message):
    with pytest.raises(SettingsError, match=f"render.options.scalar_bar_style.*{message}"):
        validate_render_options({"scalar_bar_style": style})


def test_the_editor_axis_is_linear_or_log10_from_the_floor_and_inverts() -> None:
    """The TF editor's axis: linear without a floor; with one, 1 -> 0, 10 -> 1/3, 100 -> 2/3, 1000 -> 1 over 0..1000
    (values below the floor at 0), and ``axis_value`` gives the scalars back."""
    from volviz.optics.log_scale import axis_fraction, axis_value

    assert np.allclose(axis_fraction([0.0, 250.0, 1000.0], 0.0, 1000.0), [0.0, 0.25, 1.0])
    f = axis_fraction([0.0, 0.5, 1.0, 10.0, 100.0, 1000.0], 0.0, 1000.0, 1.0)
    assert np.allclose(f, [0.0, 0.0, 0.0, 1 / 3, 2 / 3, 1.0], atol=1e-15)
    assert np.allclose(axis_value(f[2:], 0.0, 1000.0, 1.0), [1.0, 10.0, 100.0, 1000.0], rtol=1e-12)
    assert np.allclose(axis_value([0.25, 0.5], 0.0, 1000.0), [250.0, 500.0])
    assert np.allclose(axis_fraction([5.0, 50.0], 5.0, 500.0, 1.0), [0.0, 0.5])   # a positive range: from its low end


def test_clamped_count_counts_values_at_or_below_zero_not_nan() -> None:
    from volviz.optics.log_scale import clamped_count

    assert clamped_count(np.array([-1.0, 0.0, 1e-9, np.nan, 3.0])) == 2
    assert clamped_count(np.arange(5, dtype=np.uint8)) == 1
