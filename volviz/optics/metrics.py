"""Image error metrics used by every benchmark: RMSE and max abs error in 8-bit units, PSNR (docs/design.md
"Optical model and conventions").

Inputs are premultiplied float RGBA images in 0..1 (any matching shapes; all channels count). Errors are reported in
8-bit units (0..255). The error heat map reproduces the thesis's difference view (Roettger §9.2, Fig. 9.4: "error
scaled by a factor of 8 and inverted").
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["rmse", "max_abs", "psnr", "error_heatmap", "PSNR_IDENTICAL"]

PSNR_IDENTICAL = 200.0
"""PSNR reported for identical images (instead of +inf, so no metric is ever infinite)."""


def _pair(a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(a, dtype=np.float64)
    y = np.asarray(b, dtype=np.float64)
    if x.shape != y.shape:
        raise ValueError(f"images must have the same shape, got {x.shape} and {y.shape}")
    if x.size == 0:
        raise ValueError("images are empty")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("images contain NaN or Inf")
    return x, y


def rmse(a: Any, b: Any) -> float:
    """Root-mean-square difference over all pixels and channels, in 8-bit units."""
    x, y = _pair(a, b)
    return float(np.sqrt(np.mean((x - y) ** 2)) * 255.0)


def max_abs(a: Any, b: Any) -> float:
    """Largest absolute difference over all pixels and channels, in 8-bit units."""
    x, y = _pair(a, b)
    return float(np.max(np.abs(x - y)) * 255.0)


def psnr(a: Any, b: Any) -> float:
    """Peak signal-to-noise ratio in dB with peak 1.0 (= 255 in 8-bit units); identical images give 200 dB."""
    e = rmse(a, b)
    if e == 0.0:
        return PSNR_IDENTICAL
    return float(min(20.0 * math.log10(255.0 / e), PSNR_IDENTICAL))


_HEAT = np.array([[0, 0, 0], [128, 0, 0], [255, 64, 0], [255, 200, 0], [255, 255, 255]], dtype=np.float64)


def error_heatmap(a: Any, b: Any, gain: float = 8.0, style: str = "heat") -> np.ndarray:
    """uint8 RGB (H, W, 3) image of the per-pixel max abs error over channels, multiplied by ``gain``.

    ``style="heat"``: black (no error) → red → yellow → white (error × gain ≥ 1, i.e. ≥ 255/gain in 8-bit units).
    ``style="inverted"``: the thesis look, white = no error, per RGB channel 1 − gain·|Δ| (needs ≥ 3 channels).
    Inputs are (H, W) or (H, W, C) images.
    """
    x, y = _pair(a, b)
    if x.ndim not in (2, 3):
        raise ValueError(f"images must be (H, W) or (H, W, C), got shape {x.shape}")
    if not (math.isfinite(gain) and gain > 0):
        raise ValueError(f"gain must be finite and > 0, got {gain}")
    diff = np.abs(x - y)
    if style == "inverted":
        if x.ndim != 3 or x.shape[2] < 3:
            raise ValueError("style 'inverted' needs images with at least 3 channels")
        return np.round(255.0 * (1.0 - np.clip(gain * diff[..., :3], 0.0, 1.0))).astype(np.uint8)
    if style != "heat":
        raise ValueError(f"style must be 'heat' or 'inverted', got {style!r}")
    err = diff.max(axis=2) if diff.ndim == 3 else diff
    t = np.clip(gain * err, 0.0, 1.0) * (len(_HEAT) - 1)
    i0 = np.minimum(np.floor(t).astype(int), len(_HEAT) - 2)
    w = (t - i0)[..., None]
    return np.round((1.0 - w) * _HEAT[i0] + w * _HEAT[i0 + 1]).astype(np.uint8)
