"""The 2D pre-integration table with linear length scaling (Roettger §8.5, Eq. 8.2).

The table holds the exact RGBA of every segment (s_f, s_b) at one length l̄ (the average cell thickness):
RGBA_2D(s_f, s_b) = RGBA(s_f, s_b, l̄). A segment of length l is approximated by scaling linearly in l:

    I' = (l/l̄)·RGB_2D + (1 − (l/l̄)·α_2D)·I

"In practice the vertex colors are scaled by the maximum opacity value in the texture to avoid clamping for l > l̄,
and the texture entries are multiplied by the reciprocal to compensate." This module stores exactly that: the texture
``rgba = RGBA_2D / α_max`` (its α never exceeds 1) and the vertex factor v = min(l·α_max/l̄, 1). The lookup is
``v · bilinear(rgba)``; because v ≤ 1 and the texture α ≤ 1, the opacity never exceeds 1 and the transmittance never
goes negative, for any l (that is the point of the scaling; for l > l̄/α_max the result saturates instead of
extrapolating). The approximation error (linear opacity in l) is measured by ``error``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from volviz.optics import _interp
from volviz.optics._axis import ScalarAxis
from volviz.optics.integrate import integrate_segment
from volviz.optics.table3d import resolve_range
from volviz.optics.table_error import TableError, measure_error, sample_points
from volviz.optics.tf_change import changed_span, touching_pairs
from volviz.optics.transfer_function import TransferFunction

__all__ = ["Table2D", "build_table2d"]


@dataclass
class Table2D(ScalarAxis):
    """Eq. 8.2 texture ``rgba (n, n, 4)`` float32 (already divided by ``alpha_max``) and its scaling constants."""

    rgba: np.ndarray
    s_lo: float
    s_hi: float
    l_bar: float
    alpha_max: float
    tf: TransferFunction | None = None

    @property
    def vertex_scale(self) -> float:
        """Factor per unit length for the vertex color: v = min(l · vertex_scale, 1)."""
        return (self.alpha_max if self.alpha_max > 0 else 1.0) / self.l_bar

    def vertex_factor(self, l: Any) -> np.ndarray:
        """The clamped vertex color v = min(l·α_max/l̄, 1) (what a GPU would put in the vertex RGBA)."""
        v = np.clip(np.asarray(l, dtype=np.float64) * self.vertex_scale, 0.0, 1.0)
        return np.where(np.isnan(v), 0.0, v)  # NaN lengths are transparent

    def lookup(self, s_f: Any, s_b: Any, l: Any) -> np.ndarray:
        """Approximate RGBA (..., 4) float64 of segments: vertex factor × bilinear texture sample."""
        shape, (sf, sb, ll) = _interp.flat_args(s_f, s_b, l)
        out = np.empty((sf.size, 4), dtype=np.float64)
        if sf.size:
            _interp.bilinear(self.rgba, self.s_lo, self.ds, sf, sb, out)
        out *= self.vertex_factor(ll)[:, None]
        return out.reshape(shape + (4,))

    def _fill(self, tf: TransferFunction, mask: np.ndarray, raw: np.ndarray) -> None:
        ii, jj = np.nonzero(mask)
        s = self.scalars
        raw[ii, jj] = integrate_segment(tf, s[ii], s[jj], self.l_bar)

    def rebuild(self, tf: TransferFunction) -> int:
        """Recompute the entries whose scalar interval meets the changed span; returns how many were recomputed.

        α_max is re-derived; if it changed, the whole (cheap) rescale is applied to every entry.
        """
        if self.tf is None:
            raise ValueError("this table has no transfer function to compare with; build it with build_table2d")
        mask = touching_pairs(self.scalars, changed_span(self.tf, tf))
        count = int(mask.sum())
        if count:
            raw = self.rgba.astype(np.float64) * (self.alpha_max if self.alpha_max > 0 else 1.0)
            self._fill(tf, mask, raw)
            self._store(raw)
        self.tf = tf
        return count

    def _store(self, raw: np.ndarray) -> None:
        self.alpha_max = float(raw[..., 3].max(initial=0.0))
        scale = 1.0 / self.alpha_max if self.alpha_max > 0 else 1.0
        self.rgba = (raw * scale).astype(np.float32)

    def error(self, tf: TransferFunction | None = None, where: str = "centers", l_max: float | None = None,
              n_l: int = 16, **kw: Any) -> TableError:
        """Error against the reference over [s_lo, s_hi]² × [0, l_max] (default l_max = 2 l̄), n_l length samples."""
        tf = tf or self.tf
        if tf is None:
            raise ValueError("no transfer function to measure against")
        l_max = 2.0 * self.l_bar if l_max is None else float(l_max)
        pts = sample_points(self.s_lo, self.s_hi, l_max, self.n_s, n_l, where, **kw)
        return measure_error(self.lookup, tf, pts, where)


def build_table2d(tf: TransferFunction, n_s: int = 256, l_bar: float = 1.0, *, s_range: Any = None) -> Table2D:
    """Build the Eq. 8.2 table at length ``l_bar`` (set it to the average cell thickness of the mesh)."""
    if int(n_s) != n_s or n_s < 2:
        raise ValueError(f"n_s must be an integer >= 2, got {n_s}")
    l_bar = float(l_bar)
    if not (np.isfinite(l_bar) and l_bar > 0):
        raise ValueError(f"l_bar must be finite and > 0, got {l_bar}")
    lo, hi = resolve_range(tf, s_range)
    table = Table2D(np.empty((0, 0, 4), np.float32), lo, hi, l_bar, 0.0, tf)
    s = np.linspace(lo, hi, n_s)
    table._store(integrate_segment(tf, s[:, None], s[None, :], l_bar))
    return table
