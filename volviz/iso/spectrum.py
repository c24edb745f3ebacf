"""Iso-spectrum shading: the opacity of a thin layer seen at an angle, fitted by a cosine-power term (libMini note,
"Shaded Iso-Surfaces", Fig. 4).

A layer of thickness δ with extinction c has normal-incidence optical depth τ0 = c·δ; seen at angle θ to its normal the
path length is d = δ/|cos θ| (planar thin-layer approximation), so its transmittance is T(μ) = exp(−τ0/μ) with
μ = |cos θ| and its opacity α = 1 − T. (The note writes "α = exp(−c d)"; that is the transmittance — erratum: the
opacity is 1 − exp(−c d).) The note replaces the exponential by the diffuse cosine term to a power minus a constant,
which a fragment shader evaluates cheaply:

    T(μ) ≈ clamp(μ^a − b, 0, 1),   α(μ) = 1 − clamp(μ^a − b, 0, 1)

The note fixes a and fits b; here both a and b are fitted by non-linear least squares (scipy) on the note's sampling:
a sphere seen from above, x uniform in [0, 1), μ = sqrt(1 − x²), so each μ counts with its share of screen area. τ0
comes from the surface's opacity at normal incidence, α0 = 1 − exp(−τ0). The fit error is returned with the fit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = ["SpectrumFit", "fit_spectrum", "spectrum_alpha", "exact_alpha"]


@dataclass(frozen=True)
class SpectrumFit:
    """Fit of α(μ) for a layer whose normal-incidence opacity is ``opacity``; errors in opacity units (0..1)."""

    opacity: float
    tau0: float
    a: float
    b: float
    rms_error: float
    max_error: float


def exact_alpha(mu: np.ndarray | float, tau0: float) -> np.ndarray:
    """α(μ) = 1 − exp(−τ0/μ) of the planar thin layer (μ → 0 gives α → 1)."""
    m = np.maximum(np.abs(np.asarray(mu, dtype=np.float64)), 1e-12)
    return 1.0 - np.exp(-tau0 / m)


def spectrum_alpha(mu: np.ndarray | float, a: float, b: float) -> np.ndarray:
    """The note's cosine-power opacity α = 1 − clamp(μ^a − b, 0, 1)."""
    m = np.clip(np.abs(np.asarray(mu, dtype=np.float64)), 0.0, 1.0)
    return 1.0 - np.clip(m ** a - b, 0.0, 1.0)


@lru_cache(maxsize=256)
def fit_spectrum(opacity: float, n: int = 2000) -> SpectrumFit:
    """Least-squares (a, b) for a surface of normal-incidence opacity ``opacity`` in (0, 1)."""
    # SciPy's optimizer (heavy): only when a spectrum is fitted, once per opacity (cached)
    from scipy.optimize import least_squares
    o = float(opacity)
    if not 0.0 < o < 1.0:
        raise ValueError(f"iso-spectrum fit needs an opacity in (0, 1), got {opacity}")
    tau0 = -math.log1p(-o)
    x = (np.arange(n) + 0.5) / n
    mu = np.sqrt(1.0 - x * x)
    target = exact_alpha(mu, tau0)

    def resid(p: np.ndarray) -> np.ndarray:
        return spectrum_alpha(mu, p[0], p[1]) - target

    best = None
    for a0 in (0.1, 0.5, 2.0):
        r = least_squares(resid, x0=[a0, o], bounds=([1e-4, -1.0], [50.0, 1.0]), method="trf")
        if best is None or r.cost < best.cost:
            best = r
    assert best is not None  # three starts
    err = resid(best.x)
    return SpectrumFit(o, tau0, float(best.x[0]), float(best.x[1]), float(np.sqrt(np.mean(err ** 2))),
                       float(np.max(np.abs(err))))
