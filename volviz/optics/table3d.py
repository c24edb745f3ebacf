"""The full 3D pre-integration table RGBA(s_f, s_b, l) (Roettger §8.4, Eq. 8.1).

``rgba[i, j, k]`` is the exact premultiplied RGBA of the segment s_f = s_lo + i·ds → s_b = s_lo + j·ds of length
l = k·l_max/(n_l − 1), with ds = (s_hi − s_lo)/(n_s − 1). Slice k = 0 (l = 0) is zero.

Two builders:

- ``method="direct"``: every entry from ``integrate_segment`` (exact to 1e-9 in float64, stored as float32, so the
  error at the table's own sample points is the float32 rounding, ≤ 6e-8).
- ``classification="pre"`` (Roettger §8.14): entries from ``integrate_preclassified`` (the TF applied at the segment
  ends only, κ and ρ linear in between: the original projected tetrahedra), direct only, for A/B comparisons.
- ``method="incremental"`` (Weiler et al., as VTK's ``vtkUnstructuredGridPreIntegration`` does; digest §15.4): slice
  k = 1 directly, then for k ≥ 2 ``entry(i, j, k) = front(i → m, 1) over back(m → j, k − 1)`` with the scalar at
  distance Δl, m = ((k − 1) i + j)/k. VTK rounds m to the nearest index (``m_rounding="nearest"``); the default
  ``"linear"`` interpolates the two neighbouring entries instead, which is several times more accurate for the same
  cost. O(1) per entry. Its error grows with k (measured in ``docs/bench/tables.md``).

``lookup`` is trilinear (vectorised); scalars clamp to [s_lo, s_hi], l clamps to [0, l_max], NaN scalars give 0.
Build the table over the data's scalar range (``s_range``) when data can leave the TF range: the part outside the TF
range is then transparent in the table as in the reference.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numba
import numpy as np

from volviz.optics import _interp
from volviz.optics._axis import ScalarAxis
from volviz.optics.integrate import integrate_preclassified, integrate_segment
from volviz.optics.table_error import TableError, measure_error, sample_points
from volviz.optics.tf_change import changed_span, touching_pairs
from volviz.optics.transfer_function import TransferFunction

__all__ = ["Table3D", "build_table3d", "build_table3d_job"]

Progress = Callable[[float, str], None]

_METHODS = ("direct", "incremental")
_ROUNDING = ("linear", "nearest")


def _check_sizes(n_s: int, n_l: int, l_max: float) -> None:
    if int(n_s) != n_s or n_s < 2:
        raise ValueError(f"n_s must be an integer >= 2, got {n_s}")
    if int(n_l) != n_l or n_l < 2:
        raise ValueError(f"n_l must be an integer >= 2, got {n_l}")
    if not (np.isfinite(l_max) and l_max > 0):
        raise ValueError(f"l_max must be finite and > 0, got {l_max}")
    if n_s * n_s * n_l * 4 * 4 > 2 ** 31:
        raise ValueError(f"table {n_s}x{n_s}x{n_l} would need more than 2 GiB")


def resolve_range(tf: TransferFunction, s_range: Any) -> tuple[float, float]:
    """The table's scalar range: ``s_range`` if given (must be finite, lo < hi), else the TF range."""
    if s_range is None:
        return tf.range
    lo, hi = (float(v) for v in s_range)
    if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        raise ValueError(f"s_range must be finite with hi > lo, got {s_range}")
    return lo, hi


@numba.njit(cache=True, nogil=True, parallel=True)
def _incremental_fill(front, work, mask, nearest, k_start, k_stop):
    """Fill slices k_start ≤ k < k_stop (k ≥ 2) of ``work`` (n_j, L, n_i, 4) where mask[i, j]:

    entry(i, j, k) = front(i → m) over entry(m, j, k − 1), m = ((k − 1) i + j)/k, with ``front`` (n, n, 4) the
    slice of length Δl. Entries of one back scalar j depend only on entries of the same j, so the outer loop over j
    is parallel and each j's data is contiguous. Arithmetic in float64 whatever work's dtype."""
    n = work.shape[0]
    for j in numba.prange(n):
        for k in range(max(k_start, 2), k_stop):
            for i in range(n):
                if not mask[i, j]:
                    continue
                m = ((k - 1) * i + j) / k
                if nearest:
                    m0 = int(np.floor(m + 0.5))
                    w = 0.0
                else:
                    m0 = int(np.floor(m))
                    w = m - m0
                m1 = min(m0 + 1, n - 1)
                fa = (1.0 - w) * front[i, m0, 3] + w * front[i, m1, 3]
                for ch in range(4):
                    f = (1.0 - w) * front[i, m0, ch] + w * front[i, m1, ch]
                    back = (1.0 - w) * np.float64(work[j, k - 1, m0, ch]) + w * np.float64(work[j, k - 1, m1, ch])
                    work[j, k, i, ch] = f + (1.0 - fa) * back


_CHUNK_SEGMENTS = 1 << 16  # segments per progress step (2 MiB of float64 RGBA): short GIL holds, prompt cancel


_INTEGRATORS = {"post": integrate_segment, "pre": integrate_preclassified}


def _fill(tf: TransferFunction, out: np.ndarray, s: np.ndarray, ls: np.ndarray, mask: np.ndarray, method: str,
          m_rounding: str, progress: Progress | None = None, classification: str = "post") -> None:
    """(Re)compute the entries out[i, j, :, :] with mask[i, j] in the float32 table ``out`` (n, n, L, 4).

    ``progress(fraction, message)`` is called between chunks (it may raise to cancel the build)."""
    n, nl = out.shape[0], out.shape[2]
    if method == "direct":
        rows = max(1, _CHUNK_SEGMENTS // max(1, n * (nl - 1)))
        for i0 in range(0, n, rows):
            ii, jj = np.nonzero(mask[i0:i0 + rows])
            ii += i0
            if ii.size:
                out[ii, jj, 0, :] = 0.0
                out[ii, jj, 1:, :] = _INTEGRATORS[classification](tf, s[ii][:, None], s[jj][:, None], ls[None, 1:])
            if progress is not None:
                progress(min(i0 + rows, n) / n, "pre-integration table (direct)")
        return
    ii, jj = np.nonzero(mask)
    if ii.size == 0:
        return
    full = ii.size == n * n  # every pair is recomputed: no need to copy the old entries in
    # work[j, k, i] = out[i, j, k]: one back scalar's entries are contiguous
    work = np.zeros((n, nl, n, 4), np.float32) if full else np.ascontiguousarray(out.transpose(1, 2, 0, 3))
    front = out[:, :, 1, :].astype(np.float64)
    front[ii, jj] = integrate_segment(tf, s[ii], s[jj], ls[1])
    work[jj, 0, ii, :] = 0.0
    work[jj, 1, ii, :] = front[ii, jj]
    slices = max(1, _CHUNK_SEGMENTS // (n * n))
    for k0 in range(2, nl, slices):
        _incremental_fill(front, work, mask, m_rounding == "nearest", k0, min(k0 + slices, nl))
        if progress is not None:
            progress(min(k0 + slices, nl) / nl, "pre-integration table (incremental)")
    out[...] = work.transpose(2, 0, 1, 3)


@dataclass
class Table3D(ScalarAxis):
    """A 3D pre-integration table; see the module docstring for the layout."""

    rgba: np.ndarray
    s_lo: float
    s_hi: float
    l_max: float
    method: str = "direct"
    tf: TransferFunction | None = None
    m_rounding: str = "linear"
    classification: str = "post"

    @property
    def n_l(self) -> int:
        return int(self.rgba.shape[2])

    @property
    def dl(self) -> float:
        return self.l_max / (self.n_l - 1)

    @property
    def lengths(self) -> np.ndarray:
        """The table's length samples k·l_max/(n_l − 1)."""
        return np.linspace(0.0, self.l_max, self.n_l)

    def lookup(self, s_f: Any, s_b: Any, l: Any) -> np.ndarray:
        """Trilinear RGBA (..., 4) float64 at (s_f, s_b, l); clamps s to [s_lo, s_hi] and l to [0, l_max]; NaN → 0."""
        shape, (sf, sb, ll) = _interp.flat_args(s_f, s_b, l)
        out = np.empty((sf.size, 4), dtype=np.float64)
        if sf.size:
            _interp.trilinear(self.rgba, self.s_lo, self.ds, self.dl, sf, sb, ll, out)
        return out.reshape(shape + (4,))

    def rebuild(self, tf: TransferFunction) -> int:
        """Update in place for a new TF, recomputing only the (s_f, s_b) pairs whose interval meets the changed span.

        Returns the number of (i, j) pairs recomputed. Equals a fresh build with the same method (up to float64
        round-off in the pieces' split points).
        """
        if self.tf is None:
            raise ValueError("this table has no transfer function to compare with; build it with build_table3d")
        span = changed_span(self.tf, tf)
        mask = touching_pairs(self.scalars, span)
        count = int(mask.sum())
        if count:
            _fill(tf, self.rgba, self.scalars, self.lengths, mask, self.method, self.m_rounding,
                  classification=self.classification)
        self.tf = tf
        return count

    def error(self, tf: TransferFunction | None = None, where: str = "centers", **kw: Any) -> TableError:
        """Max and RMS RGBA error against the exact integral of its classification (see ``table_error``)."""
        tf = tf or self.tf
        if tf is None:
            raise ValueError("no transfer function to measure against")
        pts = sample_points(self.s_lo, self.s_hi, self.l_max, self.n_s, self.n_l, where, **kw)
        return measure_error(self.lookup, tf, pts, where, _INTEGRATORS[self.classification])


def build_table3d(tf: TransferFunction, n_s: int = 128, n_l: int = 64, l_max: float = 1.0, method: str = "direct",
                  *, s_range: Any = None, m_rounding: str = "linear", progress: Progress | None = None,
                  classification: str = "post") -> Table3D:
    """Build the 3D pre-integration table (Roettger §8.4) by direct integration or incrementally (digest §15.4).

    ``l_max`` should be the longest segment the renderer produces (VTK uses the largest cell bounding-box diagonal);
    longer segments are clamped by ``lookup``. ``progress(fraction, message)`` is called between chunks of work
    (``volviz.jobs`` passes a callable that raises to cancel). ``classification="pre"`` tabulates pre-classified
    segments instead (direct method only).
    """
    if classification not in _INTEGRATORS:
        raise ValueError(f"classification must be 'post' or 'pre', got {classification!r}")
    if classification == "pre" and method != "direct":
        raise ValueError("pre-classified tables are built with method='direct'")
    if method not in _METHODS:
        raise ValueError(f"method must be one of {_METHODS}, got {method!r}")
    if m_rounding not in _ROUNDING:
        raise ValueError(f"m_rounding must be one of {_ROUNDING}, got {m_rounding!r}")
    l_max = float(l_max)
    _check_sizes(n_s, n_l, l_max)
    lo, hi = resolve_range(tf, s_range)
    rgba = np.zeros((n_s, n_s, n_l, 4), dtype=np.float32)
    _fill(tf, rgba, np.linspace(lo, hi, n_s), np.linspace(0.0, l_max, n_l), np.ones((n_s, n_s), dtype=bool), method,
          m_rounding, progress, classification)
    return Table3D(rgba, lo, hi, l_max, method, tf, m_rounding, classification)


def build_table3d_job(tf: TransferFunction, *, progress: Progress, **kw: Any) -> Table3D:
    """``build_table3d`` for ``volviz.jobs.JobRunner.submit`` (progress is required there; it cancels by raising)."""
    return build_table3d(tf, progress=progress, **kw)
