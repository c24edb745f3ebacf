"""Which part of the scalar range a transfer-function edit touched (for incremental table rebuilds).

Roettger §8.4: "the table must be rebuilt whenever a TF changes". A table entry for the segment s_f → s_b depends on
κ and ρ only over [min(s_f, s_b), max(s_f, s_b)], so after an edit only the entries whose interval meets the changed
span need recomputing.
"""
from __future__ import annotations

import numpy as np

from volviz.optics.transfer_function import TransferFunction

__all__ = ["changed_span", "touching_pairs"]


def changed_span(old: TransferFunction, new: TransferFunction) -> tuple[float, float] | None:
    """Closed scalar interval [a, b] outside of which ``old`` and ``new`` agree exactly, or None when identical.

    Both functions are linear between the union of their control points (inside both ranges), so they agree on an
    interval between two union nodes iff they agree at both nodes. The range ends are discontinuities (transparent
    outside), so a moved end adds the whole stretch between the old and the new end.
    """
    nodes = np.union1d(old.scalars, new.scalars)
    c_old, r_old = old.evaluate(nodes)
    c_new, r_new = new.evaluate(nodes)
    differ = (r_old != r_new) | np.any(c_old != c_new, axis=-1)
    lows: list[float] = []
    highs: list[float] = []
    if np.any(differ):
        idx = np.flatnonzero(differ)
        lows.append(float(nodes[max(idx[0] - 1, 0)]))
        highs.append(float(nodes[min(idx[-1] + 1, nodes.size - 1)]))
    (lo_o, hi_o), (lo_n, hi_n) = old.range, new.range
    if lo_o != lo_n:
        lows.append(min(lo_o, lo_n))
        highs.append(max(lo_o, lo_n))
    if hi_o != hi_n:
        lows.append(min(hi_o, hi_n))
        highs.append(max(hi_o, hi_n))
    if not lows:
        return None
    return min(lows), max(highs)


def touching_pairs(nodes: np.ndarray, span: tuple[float, float] | None) -> np.ndarray:
    """Boolean (n, n) mask of node pairs (i, j) whose interval [min, max](nodes[i], nodes[j]) meets ``span``."""
    n = nodes.shape[0]
    if span is None:
        return np.zeros((n, n), dtype=bool)
    a, b = span
    lo = np.minimum(nodes[:, None], nodes[None, :])
    hi = np.maximum(nodes[:, None], nodes[None, :])
    return (lo <= b) & (hi >= a)
