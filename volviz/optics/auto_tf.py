"""A transfer function placed from the data's histogram: the legible first look at data nobody has shaped yet.

The opacity ramp runs between robust percentiles of the values (2 % and 99.5 %), computed without the background: a
histogram bin at either end of the range that holds more than ``BACKGROUND_FRACTION`` of the values (the air around a
CT scan, the zero outside a simulation's domain) is left out, and so stays transparent. The color is a cool-warm map
over the same stops. The stops are placed by histogram equalization (Chourasia & Schulze 2007, "Data centric transfer
functions for high dynamic range volume data", WSCG, §3; their equalization, without the opacity weighting): at equal
steps of the cumulative distribution of the values between the percentiles, so each of the ramp's four segments holds
a quarter of the object's samples. Evenly spaced stops put most of a long-tailed object (a density falling off over
decades, soft tissue under bone, a storm's thin edge) under the first segment, nearly transparent (docs/first-open.md
has the figures). Ties (a value holding over a quarter of the samples, as in 8-bit data) are split by
``MIN_STOP_GAP`` of the span. The peak extinction is set so that a ray crossing the data's bounding box reaches an
optical depth of about ``TARGET_DEPTH`` for the average sample, whatever the data's units and spread: the image is
neither faint nor a solid block. Values above the upper percentile keep the peak opacity and color; the function
spans the whole finite range, because volviz draws scalars outside a transfer function's range as transparent.

A background need not sit in one end bin: CT air is noisy, a flow's free stream is a narrow spike inside the range.
The dominant mode of the histogram is found and followed down both of its flanks to the valleys around it, the
valley-seeking mode separation of Prewitt & Mendelsohn (1966, "The analysis of cell images", Ann. N.Y. Acad. Sci.
128) on a lightly smoothed histogram. When that mode is narrow (at most ``MODE_WIDTH`` of the range) and holds more
than ``BACKGROUND_FRACTION`` of the values it is the background: at the low end of the range the ramp starts above
it; elsewhere (a free stream, the bright side of an inverted image) the function is centred on it, transparent there
and rising with the distance from it on either side, cool below and warm above, as the signed view is about zero.

``volviz.optics.boundary`` places the one-sided view's opacity at the data's boundaries instead (Kindlmann & Durkin
1998); on the shared volumes it was less legible by the measures of docs/first-open.md, so the equalized ramp stays.

Signed data around zero (seismic amplitudes, a velocity component, vorticity, an orbital's two signs: robust
percentiles of opposite signs, the smaller at least ``SIGNED_BALANCE`` of the larger) gets the diverging view
instead: zero transparent and white, the ramp rising towards both signs alike, blue for negative and red for
positive values. The one-sided ramp would show only the positive half.
"""
from __future__ import annotations

import numpy as np

from volviz.model.stats import constant_pad
from volviz.optics.transfer_function import TransferFunction

BACKGROUND_FRACTION = 0.2      # an end bin holding more than this share of the values is background
LOW_PERCENTILE, HIGH_PERCENTILE = 2.0, 99.5
TARGET_DEPTH = 3.0             # optical depth of the mean sample along a chord of the bounding box
MIN_DEPTH, MAX_DEPTH = 1.5, 60.0   # bounds of the peak extinction times the chord length
MAX_SAMPLES = 2_000_000        # the statistics use an even subsample of larger data
COOL_WARM = ((0.23, 0.30, 0.75), (0.55, 0.69, 0.94), (0.87, 0.87, 0.87), (0.96, 0.60, 0.48), (0.71, 0.02, 0.15))
RAMP = (0.0, 0.08, 0.3, 0.65, 1.0)     # extinction at the five color stops, as a share of the peak
MODE_WIDTH = 0.125             # a background mode spans at most this share of the value range
SMOOTHING = 5                  # bins of the box filter the mode's flanks are followed on
SIGNED_BALANCE = 0.25          # signed data: the smaller of |low| and |high| percentile over the larger, at least
MIN_STOP_GAP = 1.0 / 256       # equalized stops lie at least this share of their span apart (one histogram bin)


def finite_sample(values: np.ndarray) -> np.ndarray:
    """The finite values of ``values`` as float64, an even subsample when there are more than ``MAX_SAMPLES``."""
    flat = np.asarray(values).reshape(-1)
    if flat.size > MAX_SAMPLES:
        flat = flat[:: int(np.ceil(flat.size / MAX_SAMPLES))]
    flat = flat.astype(np.float64)
    return flat[np.isfinite(flat)]


def foreground(values: np.ndarray, bins: int = 256) -> np.ndarray:
    """``values`` without a dominant background bin at either end of their range (see the module docstring)."""
    lo, hi = float(values.min()), float(values.max())
    if hi <= lo:
        return values
    counts, edges = np.histogram(values, bins=bins, range=(lo, hi))
    keep = np.ones(values.size, dtype=bool)
    if counts[0] > BACKGROUND_FRACTION * values.size:
        keep &= values > edges[1]
    if counts[-1] > BACKGROUND_FRACTION * values.size:
        keep &= values < edges[-2]
    return values[keep] if keep.any() else values


def robust_range(values: np.ndarray) -> tuple[float, float]:
    """The 2 % and 99.5 % percentiles of the foreground values (the full range when those coincide)."""
    fg = foreground(values)
    lo, hi = (float(v) for v in np.percentile(fg, [LOW_PERCENTILE, HIGH_PERCENTILE]))
    if hi <= lo:
        lo, hi = float(values.min()), float(values.max())
    return lo, hi


def mean_chord(bounds: tuple[float, ...]) -> float:
    """The mean length of the straight lines through a box, 4 V / S (Cauchy's formula for convex bodies): the
    ray length that sets the peak extinction. A box flat in one or more axes gets its largest side instead."""
    sides = np.maximum(np.subtract(bounds[1::2], bounds[0::2]), 0.0)
    volume = float(np.prod(sides))
    surface = 2.0 * float(sides[0] * sides[1] + sides[1] * sides[2] + sides[2] * sides[0])
    if volume > 0 and surface > 0:
        return 4.0 * volume / surface
    return float(sides.max()) if sides.max() > 0 else 1.0


def auto_transfer_function(values: np.ndarray, chord: float, name: str = "auto") -> TransferFunction:
    """A transfer function for ``values`` (any shape; NaN/Inf ignored) seen through a volume whose rays are about
    ``chord`` long (``mean_chord`` of its bounding box)."""
    sample = finite_sample(values)
    chord = float(chord) if np.isfinite(chord) and chord > 0 else 1.0
    if sample.size == 0:
        return _ramp(0.0, 1.0, np.linspace(0.0, 1.0, len(RAMP)), TARGET_DEPTH / chord, name)
    full_lo, full_hi = float(sample.min()), float(sample.max())
    if full_hi <= full_lo:   # constant data: a faint uniform fog around the one value
        pad = constant_pad(full_lo)
        return _ramp(full_lo - pad, full_hi + pad, np.linspace(full_lo - pad, full_hi + pad, len(RAMP)),
                     MIN_DEPTH / chord, name)
    mode = background_mode(sample)
    if mode is not None and mode[0] > full_lo:     # a background inside the range or at its top: centred on it
        return _around(sample, full_lo, full_hi, mode, chord, name)
    span = one_sided_range(sample, mode)
    if span is not None:
        stops = equalized_stops(sample, *span)
        shape = np.interp(sample, stops, RAMP, left=0.0)
        return _ramp(full_lo, full_hi, stops, peak_extinction(float(shape.mean()), chord), name)
    lo, hi = robust_range(sample)
    reach = max(-lo, hi)
    shape = np.interp(np.abs(sample), np.linspace(0.0, reach, len(RAMP)), RAMP)
    return _diverging(full_lo, full_hi, reach, peak_extinction(float(shape.mean()), chord), name)


def one_sided_range(sample: np.ndarray, mode: tuple[float, float, float] | None = None) -> tuple[float, float] | None:
    """Where the one-sided ramp of a finite, non-constant ``sample`` runs: from above a background mode at the bottom
    of the range (``mode``, ``background_mode``'s answer) to the robust top, else the robust range; None where the
    data gets another view (a background mode inside the range, signed data)."""
    mode = background_mode(sample) if mode is None else mode
    if mode is not None and mode[0] > float(sample.min()):
        return None
    if mode is not None:                           # at the bottom: the ramp starts above it
        fg = sample[sample > mode[1]]
        if fg.size:
            lo, hi = (float(v) for v in np.percentile(fg, [LOW_PERCENTILE, HIGH_PERCENTILE]))
            if hi > lo:
                return lo, hi
    lo, hi = robust_range(sample)
    return None if is_signed(lo, hi) else (lo, hi)


def equalized_stops(sample: np.ndarray, lo: float, hi: float, n: int = len(RAMP)) -> np.ndarray:
    """``n`` stops from ``lo`` to ``hi`` at equal steps of the cumulative distribution of the values of
    ``sample`` within [``lo``, ``hi``] (histogram equalization, see the module docstring), at least ``MIN_STOP_GAP``
    of the span apart: the quantiles 0, 1/(n-1), ..., 1 of those values, ties moved up (down near ``hi``)."""
    inside = sample[(sample >= lo) & (sample <= hi)]
    stops = np.quantile(inside, np.linspace(0.0, 1.0, n)) if inside.size else np.linspace(lo, hi, n)
    stops[0], stops[-1] = lo, hi
    gap = MIN_STOP_GAP * (hi - lo)
    for i in range(1, n - 1):
        stops[i] = max(stops[i], stops[i - 1] + gap)
    for i in range(n - 2, 0, -1):
        stops[i] = min(stops[i], stops[i + 1] - gap)
    return stops


def background_mode(values: np.ndarray, bins: int = 256) -> tuple[float, float, float] | None:
    """(low edge, high edge, centre) of the background mode of ``values`` (see the module docstring), or None when
    the dominant mode is wide or holds at most ``BACKGROUND_FRACTION`` of the values."""
    lo, hi = float(values.min()), float(values.max())
    if hi <= lo:
        return None
    counts, edges = np.histogram(values, bins=bins, range=(lo, hi))
    smooth = np.convolve(counts, np.ones(SMOOTHING) / SMOOTHING, mode="same")
    peak = int(np.argmax(counts))
    a = b = peak
    while a > 0 and counts[a - 1] > 0 and smooth[a - 1] <= smooth[a]:
        a -= 1
    while b < bins - 1 and counts[b + 1] > 0 and smooth[b + 1] <= smooth[b]:
        b += 1
    if b + 1 - a > MODE_WIDTH * bins or counts[a:b + 1].sum() <= BACKGROUND_FRACTION * values.size:
        return None
    return float(edges[a]), float(edges[b + 1]), float(0.5 * (edges[peak] + edges[peak + 1]))


def peak_extinction(mean: float, chord: float) -> float:
    """The peak extinction that gives a sample of mean extinction share ``mean`` the optical depth ``TARGET_DEPTH``
    along ``chord`` (within ``MIN_DEPTH`` and ``MAX_DEPTH``)."""
    depth = TARGET_DEPTH / mean if mean > 0 else MAX_DEPTH
    return float(np.clip(depth, MIN_DEPTH, MAX_DEPTH)) / chord


def _around(sample: np.ndarray, full_lo: float, full_hi: float, mode: tuple[float, float, float], chord: float,
            name: str) -> TransferFunction:
    """Transparent over the background mode ``mode`` (low, high, centre), rising with the distance from its edges
    to the robust extremes of the values below and above it: cool below, warm above."""
    low_edge, high_edge, _ = mode
    below, above = sample[sample < low_edge], sample[sample > high_edge]
    down = low_edge - float(np.percentile(below, LOW_PERCENTILE)) if below.size else 0.0
    up = float(np.percentile(above, HIGH_PERCENTILE)) - high_edge if above.size else 0.0
    n = len(RAMP)
    stops: list[float] = []
    colors: list[list[float]] = []
    extinction: list[float] = []
    cool, warm = np.asarray(COOL_WARM[:3][::-1]), np.asarray(COOL_WARM[2:])
    for base, reach, side, palette in ((low_edge, down, -1.0, cool), (high_edge, up, 1.0, warm)):
        if reach <= 0:
            continue
        for f in np.linspace(0.0, 1.0, n):
            stops.append(base + side * f * reach)
            colors.append([float(np.interp(f, np.linspace(0.0, 1.0, 3), palette[:, c])) for c in range(3)])
            extinction.append(float(np.interp(f, np.linspace(0.0, 1.0, n), RAMP)))
    order = np.argsort(stops, kind="stable")
    stops = [stops[i] for i in order]
    colors = [colors[i] for i in order]
    extinction = [extinction[i] for i in order]
    shape = np.interp(sample, stops, extinction)
    rho_max = peak_extinction(float(shape.mean()), chord)
    return held_flat(full_lo, full_hi, stops, colors, [e * rho_max for e in extinction], name, hold_low=True)


def is_signed(lo: float, hi: float) -> bool:
    """Whether robust percentiles ``lo`` < 0 < ``hi`` are balanced enough for the diverging view."""
    return lo < 0.0 < hi and min(-lo, hi) >= SIGNED_BALANCE * max(-lo, hi)


def _diverging(full_lo: float, full_hi: float, reach: float, rho_max: float, name: str) -> TransferFunction:
    """The ramp mirrored about zero out to ``±reach``: cool colors below zero, warm above, held flat beyond."""
    n = len(RAMP)
    fractions = np.linspace(-1.0, 1.0, 2 * n - 1)
    stops = list(fractions * reach)
    colors = [list(np.interp(f, np.linspace(-1.0, 1.0, n), np.asarray(COOL_WARM)[:, c]) for c in range(3))
              for f in fractions]
    extinction = [float(np.interp(abs(f), np.linspace(0.0, 1.0, n), RAMP)) * rho_max for f in fractions]
    return held_flat(full_lo, full_hi, stops, colors, extinction, name, hold_low=True)


def _ramp(full_lo: float, full_hi: float, at: np.ndarray, rho_max: float, name: str) -> TransferFunction:
    """Cool-warm color and the extinction ``RAMP`` at the stops ``at``, held flat out to the full range."""
    stops = [float(v) for v in at]
    colors = [list(c) for c in COOL_WARM]
    extinction = [r * rho_max for r in RAMP]
    return held_flat(full_lo, full_hi, stops, colors, extinction, name)


def held_flat(full_lo: float, full_hi: float, stops: list, colors: list, extinction: list, name: str,
               hold_low: bool = False) -> TransferFunction:
    """The function over ``stops`` extended to the full range: its last stop held above; below, transparent or
    (``hold_low``) its first stop held."""
    if full_lo < stops[0]:
        stops.insert(0, full_lo)
        colors.insert(0, colors[0])
        extinction.insert(0, extinction[0] if hold_low else 0.0)
    if full_hi > stops[-1]:
        stops.append(full_hi)
        colors.append(colors[-1])
        extinction.append(extinction[-1])
    return TransferFunction(stops, colors, extinction, name=name)


def prefers_log_histogram(counts: np.ndarray) -> bool:
    """Whether a histogram is long-tailed enough to be read on a log scale: more than half of its non-empty bins
    would be drawn under 1 % of the tallest bar on a linear scale (the air of a CT scan, the empty space around a
    molecule: 62-98 % of the bins in the volumes here, 14 % for the Blunt Fin's density)."""
    counts = np.asarray(counts, dtype=np.float64)
    nonzero = counts[counts > 0]
    return bool(nonzero.size > 1 and np.mean(nonzero < 0.01 * counts.max()) > 0.5)
