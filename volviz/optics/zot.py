"""Zero-opacity test (ZOT): skip cells whose scalar interval sees no extinction (Roettger §11.5 per-node ZOT).

The digest (§15.1 A, §15.2 case 14) asks for a conservative query "is ρ ≡ 0 on [S_min, S_max]" with floor/ceil
indices, and warns that point samples can miss thin ρ peaks. This table is therefore *max-pooled*: the scalar range
is cut into ``n`` closed bins, each bin stores the exact maximum of ρ over it (a piecewise-linear function attains
its maximum at a bin end or at a control point inside), and ``pooled[i, j]`` is the maximum over bins i…j. A query
maps S_min down (floor) and S_max up (ceil) to bin indices, so the bins always cover the interval: a cell is only
reported transparent if ρ really is 0 on its whole interval (no false "transparent"; false "visible" only within one
bin of a non-zero ρ).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from volviz.optics import _interp
from volviz.optics.table3d import resolve_range
from volviz.optics.transfer_function import TransferFunction

__all__ = ["ZOTable", "build_zot", "exact_max_extinction"]


def exact_max_extinction(tf: TransferFunction, a: Any, b: Any) -> np.ndarray:
    """Exact max of ρ over the closed intervals [min(a, b), max(a, b)] (vectorised; 0 outside the TF range)."""
    shape, (sa, sb) = _interp.flat_args(a, b)
    lo, hi = np.minimum(sa, sb), np.maximum(sa, sb)
    _, r_lo = tf.evaluate(lo)
    _, r_hi = tf.evaluate(hi)
    best = np.maximum(r_lo, r_hi)
    sc, ext = tf.scalars, tf.extinction
    # max over control points inside: ext at indices [first >= lo, last <= hi]
    first = np.searchsorted(sc, lo, side="left")
    last = np.searchsorted(sc, hi, side="right") - 1
    n = sc.size
    sparse = [ext.copy()]
    while (1 << len(sparse)) <= n:
        prev, step = sparse[-1], 1 << (len(sparse) - 1)
        sparse.append(np.maximum(prev[:-step], prev[step:]) if prev.size > step else prev[:0])
    valid = first <= last
    f, g = np.where(valid, first, 0), np.where(valid, last, 0)
    level = np.floor(np.log2(np.maximum(g - f + 1, 1))).astype(int)
    inner = np.zeros_like(best)
    for lev in np.unique(level[valid]):
        sel = valid & (level == lev)
        tab = sparse[lev]
        inner[sel] = np.maximum(tab[f[sel]], tab[g[sel] - (1 << lev) + 1])
    best = np.maximum(best, np.where(valid, inner, 0.0))
    return np.where(np.isnan(sa) | np.isnan(sb), 0.0, best).reshape(shape)


@dataclass
class ZOTable:
    """Max-pooled extinction bounds: ``bins (n,)`` and ``pooled (n, n)`` (max over bins min(i,j)…max(i,j))."""

    bins: np.ndarray
    pooled: np.ndarray
    s_lo: float
    s_hi: float
    tf: TransferFunction | None = None

    @property
    def n_bins(self) -> int:
        return int(self.bins.shape[0])

    def _bin_range(self, s_min: np.ndarray, s_max: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        w = (self.s_hi - self.s_lo) / self.n_bins
        # floor/ceil with a 1e-9-bin safety margin against round-off at bin edges (conservative)
        fi = np.floor((s_min - self.s_lo) / w - 1e-9)
        fj = np.ceil((s_max - self.s_lo) / w + 1e-9) - 1
        outside = (s_max < self.s_lo) | (s_min > self.s_hi) | np.isnan(s_min) | np.isnan(s_max)
        i = np.clip(np.nan_to_num(fi), 0, self.n_bins - 1).astype(np.int64)
        j = np.clip(np.nan_to_num(fj), 0, self.n_bins - 1).astype(np.int64)
        return i, j, outside

    def max_extinction(self, s_a: Any, s_b: Any) -> np.ndarray:
        """Upper bound of ρ over the interval between s_a and s_b (vectorised; 0 outside the range or NaN)."""
        shape, (a, b) = _interp.flat_args(s_a, s_b)
        i, j, outside = self._bin_range(np.minimum(a, b), np.maximum(a, b))
        return np.where(outside, 0.0, self.pooled[i, j]).reshape(shape)

    def is_transparent(self, s_a: Any, s_b: Any) -> np.ndarray:
        """True where ρ is certainly 0 on the whole interval (conservative: never True when some ρ > 0)."""
        return self.max_extinction(s_a, s_b) <= 0.0

    def opacity_bound(self, s_a: Any, s_b: Any, l: Any) -> np.ndarray:
        """Upper bound of a segment's opacity: 1 − exp(−l · max ρ)."""
        return -np.expm1(-np.asarray(l, dtype=np.float64) * self.max_extinction(s_a, s_b))

    def error(self, tf: TransferFunction | None = None, n_random: int = 200_000, seed: int = 0) -> dict:
        """Against the exact interval maximum at random intervals (a quarter of them shorter than one bin):
        ``false_transparent`` (must be 0), ``false_visible`` (fraction, the price of conservativeness),
        ``max_overestimate`` of ρ."""
        tf = tf or self.tf
        if tf is None:
            raise ValueError("no transfer function to measure against")
        rng = np.random.default_rng(seed)
        a = rng.uniform(self.s_lo, self.s_hi, n_random)
        b = rng.uniform(self.s_lo, self.s_hi, n_random)
        short = rng.random(n_random) < 0.25
        b = np.where(short, a + rng.uniform(-1, 1, n_random) * (self.s_hi - self.s_lo) / self.n_bins, b)
        exact = exact_max_extinction(tf, a, b)
        bound = self.max_extinction(a, b)
        return {
            "false_transparent": int(np.sum((bound <= 0) & (exact > 0))),
            "false_visible": float(np.mean((bound > 0) & (exact <= 0))),
            "underestimates": int(np.sum(bound < exact * (1 - 1e-12))),
            "max_overestimate": float(np.max(bound - exact)),
            "n_samples": int(n_random),
        }

    def rebuild(self, tf: TransferFunction) -> None:
        """Recompute for a new TF (O(n²) max-pooling, a few ms at n = 256)."""
        new = build_zot(tf, self.n_bins, s_range=(self.s_lo, self.s_hi))
        self.bins, self.pooled, self.tf = new.bins, new.pooled, tf


def build_zot(tf: TransferFunction, n_bins: int = 256, *, s_range: Any = None) -> ZOTable:
    """Build the max-pooled ZOT over the TF range (or ``s_range``)."""
    if int(n_bins) != n_bins or n_bins < 1:
        raise ValueError(f"n_bins must be an integer >= 1, got {n_bins}")
    lo, hi = resolve_range(tf, s_range)
    edges = np.linspace(lo, hi, n_bins + 1)
    bins = exact_max_extinction(tf, edges[:-1], edges[1:])
    pooled = np.empty((n_bins, n_bins))
    for i in range(n_bins):
        pooled[i, i:] = np.maximum.accumulate(bins[i:])
        pooled[i:, i] = pooled[i, i:]
    return ZOTable(bins, pooled, lo, hi, tf)
