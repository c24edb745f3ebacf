"""Measured error of a table against the exact reference ``integrate_segment`` over the table's domain.

Every faster method states its error (docs/design.md "Optical model and conventions"). A table is sampled at one
of three point sets over [s_lo, s_hi]² × [0, l_max]:

- ``"nodes"``: the table's own sample points (storage and construction error only);
- ``"centers"``: the centres of the grid cells, between all neighbouring samples (worst place for multilinear
  interpolation, so this is the interpolation error);
- ``"random"``: uniformly random points (a typical error; RMS is the meaningful number).

Errors are absolute, over all four premultiplied RGBA channels, in [0, 1] units (× 255 for 8-bit units).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Callable

import numpy as np

from volviz.optics.integrate import integrate_segment
from volviz.optics.transfer_function import TransferFunction

__all__ = ["TableError", "sample_points", "measure_error"]

Lookup = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class TableError:
    """Max and RMS absolute RGBA error of a table against the reference at ``n_samples`` points of kind ``where``."""

    max_abs: float
    rms: float
    n_samples: int
    where: str

    def as_dict(self) -> dict:
        return asdict(self)


def _grid(lo: float, hi: float, n: int, where: str) -> np.ndarray:
    nodes = np.linspace(lo, hi, n)
    if where == "nodes":
        return nodes
    return 0.5 * (nodes[:-1] + nodes[1:])


def sample_points(s_lo: float, s_hi: float, l_max: float, n_s: int, n_l: int, where: str = "centers",
                  n_random: int = 200_000, seed: int = 0, max_points: int = 2_000_000
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flat arrays (s_f, s_b, l) of the evaluation points (see module docstring); ``n_l == 1`` means l = l_max only.

    Node and centre grids larger than ``max_points`` are thinned to a regular subset of rows and columns.
    """
    if where == "random":
        rng = np.random.default_rng(seed)
        return (rng.uniform(s_lo, s_hi, n_random), rng.uniform(s_lo, s_hi, n_random),
                rng.uniform(0.0, l_max, n_random) if n_l > 1 else np.full(n_random, l_max))
    if where not in ("nodes", "centers"):
        raise ValueError(f"where must be 'nodes', 'centers' or 'random', got {where!r}")
    s = _grid(s_lo, s_hi, n_s, where)
    ls = _grid(0.0, l_max, n_l, where) if n_l > 1 else np.array([l_max])
    stride = 1
    while (s[::stride].size ** 2) * ls.size > max_points:
        stride += 1
    s = s[::stride]
    sf, sb, ll = np.meshgrid(s, s, ls, indexing="ij")
    return sf.ravel(), sb.ravel(), ll.ravel()


def measure_error(lookup: Lookup, tf: TransferFunction, points: tuple[np.ndarray, np.ndarray, np.ndarray],
                  where: str = "", integrator: Any = None) -> TableError:
    """Compare ``lookup(s_f, s_b, l)`` (..., 4) with ``integrator`` (default ``integrate_segment``) at the points."""
    sf, sb, ll = points
    ref = (integrator or integrate_segment)(tf, sf, sb, ll)
    got = np.asarray(lookup(sf, sb, ll), dtype=np.float64)
    if got.shape != ref.shape:
        raise ValueError(f"lookup returned shape {got.shape}, expected {ref.shape}")
    if not np.all(np.isfinite(got)):
        raise ValueError("lookup returned NaN or Inf")
    diff = np.abs(got - ref)
    return TableError(float(diff.max(initial=0.0)), float(np.sqrt(np.mean(diff * diff))) if diff.size else 0.0,
                      int(sf.size), where)
