"""A log color scale: a transfer function applied to log10 of the scalar (the component setting ``log_scale``).

The control points keep their data values; color and extinction are interpolated between them in log10 of the
value, as ParaView's "log scale" does. Renderers interpolate transfer functions linearly in the value, so the mapping
is handed to them as a function resampled at ``LOG_SAMPLES`` geometrically spaced values and at its own knots
(piecewise linear between neighbours a factor (hi/lo)^(1/LOG_SAMPLES) apart).
Log10 has no value at or below 0: those scalars, and control points there, are clamped to the smallest positive
value (``floor``, the data's), and take its color and opacity.
"""
from __future__ import annotations

import numpy as np

from volviz.optics.transfer_function import TransferFunction

LOG_SAMPLES = 256


def positive_floor(values: np.ndarray, lo: float, hi: float) -> float:
    """The smallest positive value log scale maps: the smallest positive finite value of ``values`` at or above
    ``lo`` (the range's low end when that is positive); ``hi * 1e-6`` when none is positive but ``hi``."""
    if lo > 0:
        return float(lo)
    v = np.asarray(values).reshape(-1)
    positive = v[(v > 0) & np.isfinite(v)] if v.dtype.kind == "f" else v[v > 0]
    if positive.size:
        return float(positive.min())
    return float(hi) * 1e-6 if hi > 0 else 1.0


def log_mapped(tf: TransferFunction, floor: float, samples: int = LOG_SAMPLES) -> TransferFunction:
    """``tf`` applied to log10 of the scalar, as a transfer function of the scalar itself (see the module's
    docstring): defined over the same range, values from the range's low end up to ``floor`` take the color at
    ``floor``. A range that ends at or below ``floor`` has nothing to map logarithmically: ``tf`` is returned."""
    lo, hi = tf.range
    floor = max(float(floor), float(lo))
    if not (floor > 0 and hi > floor):
        return tf
    knots = np.log10(np.maximum(tf.scalars, floor))
    inside = tf.scalars[(tf.scalars > floor) & (tf.scalars < hi)]
    values = np.union1d(np.geomspace(floor, hi, int(samples)), inside)   # the knots themselves exact
    logs = np.log10(values)
    colors = np.stack([np.interp(logs, knots, tf.colors[:, ch]) for ch in range(3)], axis=1)
    extinction = np.interp(logs, knots, tf.extinction)
    if lo < floor:  # the clamped part: constant at the floor's color
        values = np.concatenate([[lo], values])
        colors = np.concatenate([colors[:1], colors])
        extinction = np.concatenate([extinction[:1], extinction])
    values[0 if lo >= floor else 1], values[-1] = floor, hi   # exact ends (geomspace's may differ in the last bit)
    return TransferFunction(values, colors, extinction, name=tf.name)


def log_ticks(lo: float, hi: float) -> np.ndarray:
    """Label values of a log scale from ``lo`` to ``hi`` (> 0): the powers of ten between them, with 2x and 5x
    each decade when there are fewer than three powers, and both ends (a tick too near an end is left out)."""
    if not (lo > 0 and hi > lo):
        return np.array([lo, hi], dtype=np.float64)
    decades = np.arange(np.floor(np.log10(lo)), np.ceil(np.log10(hi)) + 1)
    for mantissas in ((1.0,), (1.0, 2.0, 5.0), (1.0, 2.0, 3.0, 5.0)):
        ticks = np.array([m * 10.0 ** d for d in decades for m in mantissas])
        gap = 0.06 * np.log10(hi / lo)   # a tick this close (in log10) to an end would overprint its label
        ticks = ticks[(np.log10(ticks / lo) > gap) & (np.log10(hi / ticks) > gap)]
        if ticks.size >= 3:
            break
    return np.unique(np.concatenate([[lo], ticks, [hi]]))


def axis_fraction(s: np.ndarray | float, lo: float, hi: float, floor: float | None = None) -> np.ndarray:
    """Where scalars ``s`` stand along an axis from ``lo`` to ``hi`` (0 at ``lo``, 1 at ``hi``): linear, or with a
    ``floor`` (the log scale's smallest positive value) in log10 from ``max(lo, floor)``, values below it at 0 (the
    TF editor's axis, which then reads as the volume is colored)."""
    v = np.asarray(s, dtype=np.float64)
    if floor is None:
        return (v - lo) / (hi - lo)
    a, b = _log_span(lo, hi, floor)
    return (np.log10(np.maximum(v, 10.0 ** a)) - a) / (b - a)


def axis_value(fraction: np.ndarray | float, lo: float, hi: float, floor: float | None = None) -> np.ndarray:
    """The scalar at ``fraction`` of the axis of ``axis_fraction`` (its inverse above the floor)."""
    f = np.asarray(fraction, dtype=np.float64)
    if floor is None:
        return lo + f * (hi - lo)
    a, b = _log_span(lo, hi, floor)
    return 10.0 ** (a + f * (b - a))


def _log_span(lo: float, hi: float, floor: float) -> tuple[float, float]:
    a = float(np.log10(max(lo, floor)))
    b = float(np.log10(hi)) if hi > 10.0 ** a else a + 1.0
    return a, b


def clamped_count(values: np.ndarray) -> int:
    """How many of ``values`` a log scale cannot map (at or below 0; NaN is not counted): drawn at its floor."""
    v = np.asarray(values)
    return int(np.count_nonzero(v <= 0))
