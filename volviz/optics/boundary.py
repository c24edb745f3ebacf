"""Where the boundaries between materials lie in a regular volume's value range: the opacity of the first look.

Kindlmann & Durkin (1998, "Semi-automatic generation of transfer functions for direct volume rendering", IEEE
Symposium on Volume Visualization, §3-4) model a boundary as a blurred step, v(x) = v1 + (v2 - v1) Φ(x / σ) across it.
Then, per data value v, the mean gradient magnitude g(v) peaks at the boundary's middle and the mean second
directional derivative along the gradient h(v) changes sign there, and the signed distance from the boundary of a
sample with value v is p(v) = -σ² h(v) / g(v) (§4.1), with σ = g_max / (√e h_max) (the blur of the model, §4.2).
Opacity is a bump of p: highest where p(v) = 0, falling to zero at |p| = σ (the boundary emphasis function, §4.3).
Homogeneous regions (a material's inside, noise) get none: as with the paper's g_thresh, g(v) is taken less a floor
(``GRADIENT_FLOOR`` of g_max), and a bin at or under it has no boundary.

``boundary_transfer_function`` is ``volviz.optics.auto_tf``'s one-sided view (range, colours, background, optical
depth) with this opacity instead of its ramp. It is not the first look's rule: on the shared regular volumes it drew
fewer visible pixels and made the histogram's main modes (materials) transparent (docs/first-open.md, measured with
``volviz bench first_open --boundary-rule``); it stays for that comparison and for data whose materials hide their
boundaries.

Derivatives are central differences (``numpy.gradient``) on an even subsample of at most ``MAX_SAMPLES`` points,
in the grid's own units; h is the derivative of |∇f| along ∇f, which equals ∇fᵀ H ∇f / |∇f|² (§3.2).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np

from volviz.model.datasets import RegularVolume, TimeSeries
from volviz.optics.auto_tf import (COOL_WARM, auto_transfer_function, finite_sample, held_flat, one_sided_range,
                                   peak_extinction)
from volviz.optics.transfer_function import TransferFunction

MAX_SAMPLES = 2_000_000        # derivatives on an even subsample of at most this many grid points
MAX_STEPS = 4                  # a time series: the boundaries of at most this many evenly spaced steps
GRADIENT_FLOOR = 0.2           # g(v) under this share of its peak: a homogeneous region (see the module docstring)
MIN_BIN_SHARE = 1e-4           # a bin with fewer samples than this share of them has no reliable mean
SMOOTHING = 3                  # bins of the count-weighted box filter on g(v) and h(v)
BINS = 32                      # value bins (and stops of the transfer function) between the robust percentiles


@dataclass(frozen=True)
class BoundaryProfile:
    """Per value bin: sample count, mean gradient magnitude g, mean second directional derivative h, the boundary
    distance p = -σ² h / g (NaN where no boundary: few samples or g at the floor), and the model's blur σ."""

    edges: np.ndarray
    counts: np.ndarray
    g: np.ndarray
    h: np.ndarray
    position: np.ndarray
    sigma: float

    @property
    def centres(self) -> np.ndarray:
        return 0.5 * (self.edges[1:] + self.edges[:-1])

    def emphasis(self) -> np.ndarray:
        """The boundary emphasis per bin: 1 - |p| / σ, clipped to [0, 1]; 0 where p is NaN (§4.3)."""
        bump = 1.0 - np.abs(self.position) / self.sigma if self.sigma > 0 else np.zeros_like(self.position)
        return np.where(np.isfinite(bump), np.clip(bump, 0.0, 1.0), 0.0)


def regular_fields(dataset: Any) -> Optional[tuple[list[np.ndarray], tuple[float, float, float]]]:
    """The 3-D scalar arrays (one per step, at most ``MAX_STEPS`` of a time series) and the grid spacing of a
    regular volume, or None for any other dataset (meshes keep the histogram rule)."""
    if isinstance(dataset, TimeSeries):
        if len(dataset) == 0 or not isinstance(dataset.frame(0), RegularVolume):
            return None
        steps = np.unique(np.linspace(0, len(dataset) - 1, min(MAX_STEPS, len(dataset))).round().astype(int))
        frames = [dataset.frame(int(i)) for i in steps]
        volumes = [f for f in frames if isinstance(f, RegularVolume)]
        return [np.asarray(v.data) for v in volumes], _spacing(volumes[0])
    if isinstance(dataset, RegularVolume):
        return [np.asarray(dataset.data)], _spacing(dataset)
    return None


def _spacing(volume: Any) -> tuple[float, float, float]:
    sx, sy, sz = (float(s) for s in volume.spacing)
    return sx, sy, sz


def derivatives(field: np.ndarray, spacing: Sequence[float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(value, |∇f|, second derivative along ∇f) at the finite points of an even subsample of the 3-D ``field``
    (every k-th point along each axis, k the least that leaves at most ``MAX_SAMPLES``); flat float64 arrays."""
    field = np.asarray(field)
    if field.ndim != 3 or min(field.shape) < 3:
        empty = np.zeros(0)
        return empty, empty, empty
    k = max(1, int(np.ceil((field.size / MAX_SAMPLES) ** (1.0 / 3.0) - 1e-9)))
    f = np.ascontiguousarray(field[::k, ::k, ::k], dtype=np.float32)
    axes = [i for i in range(3) if f.shape[i] >= 3]             # a subsample too thin along an axis skips it
    step = [float(spacing[i]) * k for i in axes]
    grad = np.gradient(f, *step, axis=axes)
    grad = grad if isinstance(grad, (list, tuple)) else [grad]
    magnitude = np.sqrt(sum(c.astype(np.float64) ** 2 for c in grad))
    slope = np.gradient(magnitude, *step, axis=axes)
    slope = slope if isinstance(slope, (list, tuple)) else [slope]
    with np.errstate(invalid="ignore", divide="ignore"):
        along = sum(s * c for s, c in zip(slope, grad)) / magnitude
    along = np.where(magnitude > 0, along, 0.0)
    ok = np.isfinite(f) & np.isfinite(magnitude) & np.isfinite(along)
    return f[ok].astype(np.float64), magnitude[ok], along[ok]


def boundary_profile(fields: Sequence[np.ndarray], spacing: Sequence[float], lo: float, hi: float,
                     bins: int = 32) -> Optional[BoundaryProfile]:
    """The ``BoundaryProfile`` of ``fields`` (3-D arrays on one grid of ``spacing``) over ``bins`` equal bins of
    [``lo``, ``hi``], or None when no bin shows a boundary (constant or too small data)."""
    parts = [derivatives(f, spacing) for f in fields]
    values = np.concatenate([p[0] for p in parts])
    if values.size == 0 or not hi > lo:
        return None
    g_all, h_all = np.concatenate([p[1] for p in parts]), np.concatenate([p[2] for p in parts])
    inside = (values >= lo) & (values <= hi)
    index = np.minimum(((values[inside] - lo) / (hi - lo) * bins).astype(np.int64), bins - 1)
    counts = np.bincount(index, minlength=bins).astype(np.float64)
    box = np.ones(SMOOTHING)
    weight = np.convolve(counts, box, mode="same")
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.convolve(np.bincount(index, g_all[inside], bins), box, mode="same") / weight
        h = np.convolve(np.bincount(index, h_all[inside], bins), box, mode="same") / weight
    reliable = counts >= max(MIN_BIN_SHARE * values.size, 1.0)
    if not reliable.any() or not np.nanmax(np.where(reliable, g, np.nan)) > 0:
        return None
    g_max = float(np.nanmax(np.where(reliable, g, np.nan)))
    h_max = float(np.nanmax(np.where(reliable, np.abs(h), np.nan)))
    sigma = g_max / (math.exp(0.5) * h_max) if h_max > 0 else 0.0     # sqrt(e)
    floor = GRADIENT_FLOOR * g_max
    with np.errstate(invalid="ignore", divide="ignore"):
        position = np.where(reliable & (g > floor), -sigma ** 2 * h / (g - floor), np.nan)
    return BoundaryProfile(np.linspace(lo, hi, bins + 1), counts, g, h, position, float(sigma))


def boundary_transfer_function(values: np.ndarray, chord: float, grid: tuple[Sequence[np.ndarray], Sequence[float]],
                               name: str = "boundary") -> TransferFunction:
    """``auto_transfer_function``'s one-sided view of ``values`` (same range, cool-warm map, background left out,
    optical-depth normalisation for rays ``chord`` long) with the extinction at ``BINS`` stops the boundary emphasis
    of ``grid`` (the values' 3-D arrays and spacing, ``regular_fields``) instead of the ramp. Data that gets another
    view (signed, a background mode inside the range, constant) or shows no boundary gets ``auto_transfer_function``."""
    sample = finite_sample(values)
    span = one_sided_range(sample) if sample.size and sample.max() > sample.min() else None
    profile = boundary_profile(grid[0], grid[1], span[0], span[1], BINS) if span is not None else None
    if span is None or profile is None or not profile.emphasis().any():
        return auto_transfer_function(values, chord, name)
    lo, hi = span
    emphasis = profile.emphasis()
    stops = [lo] + list(profile.centres) + [hi]
    extinction = [0.0] + list(emphasis) + [float(emphasis[-1])]
    shape = np.interp(sample, stops, extinction, left=0.0)
    rho_max = peak_extinction(float(shape.mean()), float(chord) if np.isfinite(chord) and chord > 0 else 1.0)
    palette = np.asarray(COOL_WARM)
    where = (np.asarray(stops) - lo) / (hi - lo)
    colors = [[float(np.interp(w, np.linspace(0.0, 1.0, len(palette)), palette[:, c])) for c in range(3)]
              for w in where]
    return held_flat(float(sample.min()), float(sample.max()), stops, colors, [e * rho_max for e in extinction],
                     name)
