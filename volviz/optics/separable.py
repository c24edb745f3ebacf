"""Separable pre-integration (Roettger Ch. 9, §9.1; Guthe §1.5): exact opacity from ρ̂, color as a polynomial in l.

Opacity (§9.1.1, Eqs. 9.1–9.2), exact up to table resolution:
    ρ̂(s_f, s_b) = ∫_0^1 ρ(s_f + t(s_b − s_f)) dt,      α = 1 − exp(−l ρ̂)
ρ̂ is computed per pair as the exact piecewise integral of ρ divided by |s_b − s_f| (a sum of non-negative piece
terms, so there is no cancellation; the diagonal s_f = s_b is ρ(s_f), the limit of the integral-function quotient).
The exponential is evaluated exactly at lookup (modern hardware does not need the 16-bit α_1D texture).

Color (§9.1.2): the normalised chromaticity Ĉ_l = C(s_f, s_b, l)/α(s_f, s_b, l) is sampled at l = (i/n)·l_max,
i = 0…n (the digest's ERRATUM: the thesis prints l = i/l_max), and interpolated by a polynomial of degree n = 1, 2 or 4
in u = l/l_max:  C ≈ α · Σ_i C̃_i(s_f, s_b) u^i.  The sample at l → 0 is the analytic limit
    Ĉ_0 = ∫_0^1 κρ dt / ∫_0^1 ρ dt
(0/0 resolved: where ∫ρ = 0 every Ĉ_l is set to the mean of κ over the segment, the limit for vanishing uniform ρ;
it is harmless since α = 0 there, and it keeps the polynomial and the interpolation NaN-free). Where α(l_i) < 1e-10,
Ĉ_0 is used for the sample (|Ĉ_l − Ĉ_0| = O(lρ̂) ≤ 1e-10 there). At lookup u is clamped to [0, 1] (no polynomial
extrapolation beyond l_max; α still uses the true l) and Ĉ is clamped to [0, max κ] per channel (Ĉ is an average
of κ, so the clamp only removes polynomial overshoot).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from volviz.optics import _interp
from volviz.optics._axis import ScalarAxis
from volviz.optics.integrate import integrate_segment
from volviz.optics.table3d import resolve_range
from volviz.optics.table_error import TableError, measure_error, sample_points
from volviz.optics.tf_change import changed_span, touching_pairs
from volviz.optics.transfer_function import TransferFunction

__all__ = ["SeparableTable", "build_separable", "segment_averages"]

_DEGREES = (1, 2, 4)
_TINY_ALPHA = 1e-10


@numba.njit(cache=True, nogil=True)
def _averages_one(sc, col, ext, a, b, out):
    """out = (ρ̂, Ĉ_0 (3), mean κ (3)) of the scalar interval [a, b] (a ≤ b)."""
    n = sc.shape[0]
    for ch in range(7):
        out[ch] = 0.0
    if a != a or b != b or b < sc[0] or a > sc[n - 1]:
        return
    if a == b:
        k = min(max(np.searchsorted(sc, a, side="right") - 1, 0), n - 2)
        w = (a - sc[k]) / (sc[k + 1] - sc[k])
        rho = ext[k] + w * (ext[k + 1] - ext[k])
        out[0] = rho
        for ch in range(3):
            kap = col[k, ch] + w * (col[k + 1, ch] - col[k, ch])
            out[1 + ch] = kap
            out[4 + ch] = kap
        return
    k = max(np.searchsorted(sc, a, side="right") - 1, 0)
    r_int = 0.0
    kr_int = np.zeros(3)
    k_int = np.zeros(3)
    while k <= n - 2 and sc[k] < b:
        x0 = max(a, sc[k])
        x1 = min(b, sc[k + 1])
        if x1 > x0:
            w = sc[k + 1] - sc[k]
            w0 = (x0 - sc[k]) / w
            w1 = (x1 - sc[k]) / w
            r0 = ext[k] + w0 * (ext[k + 1] - ext[k])
            r1 = ext[k] + w1 * (ext[k + 1] - ext[k])
            d = x1 - x0
            r_int += 0.5 * d * (r0 + r1)
            for ch in range(3):
                c0 = col[k, ch] + w0 * (col[k + 1, ch] - col[k, ch])
                c1 = col[k, ch] + w1 * (col[k + 1, ch] - col[k, ch])
                kr_int[ch] += d * (2.0 * c0 * r0 + c0 * r1 + c1 * r0 + 2.0 * c1 * r1) / 6.0
                k_int[ch] += 0.5 * d * (c0 + c1)
        k += 1
    span = b - a
    out[0] = r_int / span
    for ch in range(3):
        out[4 + ch] = k_int[ch] / span
        out[1 + ch] = kr_int[ch] / r_int if r_int > 0.0 else out[4 + ch]


@numba.njit(cache=True, nogil=True, parallel=True)
def _averages(sc, col, ext, a, b, out):
    for m in numba.prange(a.shape[0]):
        lo = min(a[m], b[m])
        hi = max(a[m], b[m])
        _averages_one(sc, col, ext, lo, hi, out[m])


def segment_averages(tf: TransferFunction, s_f: Any, s_b: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact (ρ̂ (...), Ĉ_0 (..., 3), mean κ (..., 3)) of segments s_f → s_b (Eq. 9.1 and the §9.1.2 l → 0 limit)."""
    shape, (sf, sb) = _interp.flat_args(s_f, s_b)
    out = np.empty((sf.size, 7), dtype=np.float64)
    if sf.size:
        _averages(np.ascontiguousarray(tf.scalars), np.ascontiguousarray(tf.colors),
                  np.ascontiguousarray(tf.extinction), sf, sb, out)
    res = out.reshape(shape + (7,))
    return res[..., 0], res[..., 1:4], res[..., 4:7]


def _vandermonde_inverse(degree: int) -> np.ndarray:
    u = np.arange(degree + 1) / degree
    return np.linalg.inv(np.vander(u, degree + 1, increasing=True))


@dataclass
class SeparableTable(ScalarAxis):
    """``data (n, n, 1 + 3(deg + 1))`` float32: channel 0 is ρ̂, then the coefficients C̃_0…C̃_deg (RGB each)."""

    _axis_field = "data"

    data: np.ndarray
    s_lo: float
    s_hi: float
    l_max: float
    degree: int
    kappa_max: np.ndarray
    tf: TransferFunction | None = None

    @property
    def rho_hat(self) -> np.ndarray:
        """The ρ̂ table (Eq. 9.1), (n, n)."""
        return self.data[..., 0]

    @property
    def coefficients(self) -> np.ndarray:
        """C̃_i as (n, n, degree + 1, 3)."""
        return self.data[..., 1:].reshape(self.n_s, self.n_s, self.degree + 1, 3)

    def lookup(self, s_f: Any, s_b: Any, l: Any) -> np.ndarray:
        """RGBA (..., 4): α = 1 − exp(−l ρ̂) (exact but for bilinear ρ̂), color = α · clamp(Σ C̃_i u^i)."""
        shape, (sf, sb, ll) = _interp.flat_args(s_f, s_b, l)
        vals = np.empty((sf.size, self.data.shape[2]), dtype=np.float64)
        if sf.size:
            _interp.bilinear(self.data, self.s_lo, self.ds, sf, sb, vals)
        ll = np.where(np.isnan(ll), 0.0, np.clip(ll, 0.0, None))  # NaN lengths are transparent
        alpha = -np.expm1(-ll * vals[:, 0])
        u = np.clip(ll / self.l_max, 0.0, 1.0)
        coef = vals[:, 1:].reshape(-1, self.degree + 1, 3)
        chroma = coef[:, self.degree, :]
        for i in range(self.degree - 1, -1, -1):
            chroma = chroma * u[:, None] + coef[:, i, :]
        chroma = np.clip(chroma, 0.0, self.kappa_max[None, :])
        out = np.empty((sf.size, 4), dtype=np.float64)
        out[:, :3] = chroma * alpha[:, None]
        out[:, 3] = alpha
        return out.reshape(shape + (4,))

    def _fill(self, tf: TransferFunction, mask: np.ndarray, data: np.ndarray) -> None:
        ii, jj = np.nonzero(mask)
        s = self.scalars
        sf, sb = s[ii], s[jj]
        rho_hat, c0, kmean = segment_averages(tf, sf, sb)
        samples = np.empty((ii.size, self.degree + 1, 3))
        samples[:, 0] = c0
        no_rho = rho_hat <= 0.0
        for i in range(1, self.degree + 1):
            rgba = integrate_segment(tf, sf, sb, (i / self.degree) * self.l_max)
            a = rgba[:, 3:4]
            ok = a >= _TINY_ALPHA
            samples[:, i] = np.where(ok, rgba[:, :3] / np.where(ok, a, 1.0), c0)
        samples[no_rho] = kmean[no_rho][:, None, :]
        coef = np.einsum("ij,mjc->mic", _vandermonde_inverse(self.degree), samples)
        data[ii, jj, 0] = rho_hat
        data[ii, jj, 1:] = coef.reshape(ii.size, -1)

    def rebuild(self, tf: TransferFunction) -> int:
        """Recompute only the pairs whose scalar interval meets the changed span; returns how many."""
        if self.tf is None:
            raise ValueError("this table has no transfer function to compare with; build it with build_separable")
        mask = touching_pairs(self.scalars, changed_span(self.tf, tf))
        count = int(mask.sum())
        if count:
            data = self.data.astype(np.float64)
            self._fill(tf, mask, data)
            self.data = data.astype(np.float32)
        self.kappa_max = tf.colors.max(axis=0).copy()
        self.tf = tf
        return count

    def error(self, tf: TransferFunction | None = None, where: str = "centers", n_l: int = 16, **kw: Any
              ) -> TableError:
        """Error against the reference over [s_lo, s_hi]² × [0, l_max] with n_l length samples."""
        tf = tf or self.tf
        if tf is None:
            raise ValueError("no transfer function to measure against")
        pts = sample_points(self.s_lo, self.s_hi, self.l_max, self.n_s, n_l, where, **kw)
        return measure_error(self.lookup, tf, pts, where)


def build_separable(tf: TransferFunction, n_s: int = 512, l_max: float = 1.0, degree: int = 2, *,
                    s_range: Any = None) -> SeparableTable:
    """Build the Ch. 9 tables: ρ̂ and the color polynomial of ``degree`` 1, 2 (recommended) or 4 over [0, l_max]."""
    if degree not in _DEGREES:
        raise ValueError(f"degree must be one of {_DEGREES}, got {degree}")
    if int(n_s) != n_s or n_s < 2:
        raise ValueError(f"n_s must be an integer >= 2, got {n_s}")
    l_max = float(l_max)
    if not (np.isfinite(l_max) and l_max > 0):
        raise ValueError(f"l_max must be finite and > 0, got {l_max}")
    lo, hi = resolve_range(tf, s_range)
    table = SeparableTable(np.zeros((n_s, n_s, 1 + 3 * (degree + 1)), np.float32), lo, hi, l_max, degree,
                           tf.colors.max(axis=0).copy(), tf)
    data = np.zeros(table.data.shape, dtype=np.float64)
    table._fill(tf, np.ones((n_s, n_s), dtype=bool), data)
    table.data = data.astype(np.float32)
    return table
