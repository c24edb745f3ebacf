"""Image error metrics in 8-bit units, PSNR and the ×8 error heat map."""
from __future__ import annotations

import math

import numpy as np
import pytest

from volviz.optics.metrics import PSNR_IDENTICAL, error_heatmap, max_abs, psnr, rmse


def test_known_values():
    a = np.zeros((4, 4, 4))
    b = a.copy()
    b[0, 0, 0] = 1.0  # one channel of one pixel fully off: mse = 1/64
    assert rmse(a, b) == pytest.approx(255.0 / 8.0)
    assert max_abs(a, b) == pytest.approx(255.0)
    assert psnr(a, b) == pytest.approx(10 * math.log10(64.0))
    c = np.full((2, 3, 4), 0.5)
    d = c + 2.0 / 255.0
    assert rmse(c, d) == pytest.approx(2.0) and max_abs(c, d) == pytest.approx(2.0)
    assert psnr(c, c) == PSNR_IDENTICAL and rmse(c, c) == 0.0


def test_bad_inputs():
    with pytest.raises(ValueError, match="same shape"):
        rmse(np.zeros((2, 2)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="NaN"):
        max_abs(np.array([np.nan]), np.array([0.0]))
    with pytest.raises(ValueError, match="empty"):
        psnr(np.zeros(0), np.zeros(0))
    with pytest.raises(ValueError, match="gain"):
        error_heatmap(np.zeros((2, 2)), np.zeros((2, 2)), gain=0)


def test_heatmap_scales_by_gain_and_saturates():
    a = np.zeros((2, 3, 4))
    b = a.copy()
    b[0, 1, 2] = 1.0 / 8.0  # × 8 = full scale
    b[1, 2, 0] = 1.0 / 32.0  # × 8 = quarter scale
    heat = error_heatmap(a, b)
    assert heat.shape == (2, 3, 3) and heat.dtype == np.uint8
    assert heat[0, 0].tolist() == [0, 0, 0] and heat[0, 1].tolist() == [255, 255, 255]
    assert heat[1, 2].tolist() == [128, 0, 0]  # first ramp step: dark red
    inv = error_heatmap(a, b, style="inverted")
    assert inv[0, 0].tolist() == [255, 255, 255] and inv[0, 1].tolist() == [255, 255, 0]
    assert inv[1, 2].tolist() == [191, 255, 255]
    assert error_heatmap(a[..., 0], b[..., 0]).shape == (2, 3, 3)
