"""Isosurface textures indexed by (s_f, s_b) (Roettger §8.8–8.10) and their Heaviside limit (§8.13).

A projected (sub-)tetrahedron's thick part has scalar s_f on its front face and s_b on its back face. An isosurface
s_iso is hit by the ray iff it lies between them; §8.13 shows this is the limit of the 3D table for a TF
ρ = C δ(s − s_iso) as C → ∞:

    α = H((s_iso − s_f)/(s_b − s_f)) · H((s_iso − s_b)/(s_f − s_b))         (independent of l)

Conventions fixed here (the thesis leaves them open, digest §15.2 case 3): H(0) = ½, so an isovalue exactly on a
face counts half (the value texture filtering converges to); on the diagonal s_f = s_b no isosurface is crossed
(a ray parallel to the surface; α = 0, no division by s_b − s_f happens); ``thicken`` > 0 widens every surface to the
slab [s_iso − thicken, s_iso + thicken], counted fully wherever the segment's interval meets it (the §8.8 fix for
gaps between neighbouring patches; diagonal texels inside the slab are then opaque).

Several colored isosurfaces go into one texture (§8.10): the crossed surfaces are composited front to back in ray
order (increasing values for s_f < s_b, decreasing for s_f > s_b), each with its opacity; the color seen from the
low side (s_f < s_b, looking along the gradient) and from the high side can differ.

Smooth shading (§8.9) blends the shaded front- and back-face triangles with the front-face weight of the front-most
crossed surface, w = (s_iso − s_b)/(s_f − s_b) (back-face weight 1 − w).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from volviz.optics import _interp
from volviz.optics._axis import ScalarAxis
from volviz.optics.table_error import TableError, measure_error, sample_points
from volviz.optics.transfer_function import TransferFunction

__all__ = ["IsoSurface", "IsoTable", "build_iso_table", "heaviside_alpha", "iso_peaks_tf"]


@dataclass(frozen=True)
class IsoSurface:
    """One isosurface: value, color seen from the low side, optional color from the high side, opacity."""

    value: float
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    opacity: float = 1.0
    back_color: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if not np.isfinite(self.value):
            raise ValueError(f"isovalue must be finite, got {self.value}")
        if not (0.0 <= self.opacity <= 1.0):
            raise ValueError(f"isosurface opacity must be in [0, 1], got {self.opacity}")
        for c in (self.color, self.back_color if self.back_color is not None else self.color):
            if len(c) != 3 or min(c) < 0 or not np.all(np.isfinite(c)):
                raise ValueError(f"isosurface color must be 3 finite values >= 0, got {c}")


def heaviside_alpha(s_f: Any, s_b: Any, s_iso: float, thicken: float = 0.0) -> np.ndarray:
    """The §8.13 limit α(s_f, s_b) for one isovalue with the conventions of the module docstring (NaN → 0)."""
    sf = np.asarray(s_f, dtype=np.float64)
    sb = np.asarray(s_b, dtype=np.float64)
    lo = np.minimum(sf, sb)
    hi = np.maximum(sf, sb)
    if thicken > 0:
        out = ((lo - thicken <= s_iso) & (s_iso <= hi + thicken)).astype(np.float64)
    else:
        h_lo = np.where(lo < s_iso, 1.0, np.where(lo == s_iso, 0.5, 0.0))
        h_hi = np.where(hi > s_iso, 1.0, np.where(hi == s_iso, 0.5, 0.0))
        out = np.where(lo < hi, h_lo * h_hi, 0.0)
    return np.where(np.isnan(sf) | np.isnan(sb), 0.0, out)


@dataclass
class IsoTable(ScalarAxis):
    """``rgba (n, n, 4)`` premultiplied flat texture and ``front_weight (n, n)`` for smooth shading (float32)."""

    rgba: np.ndarray
    front_weight: np.ndarray
    s_lo: float
    s_hi: float
    isosurfaces: tuple[IsoSurface, ...]
    thicken: float = 0.0

    def smooth_front_rgba(self) -> np.ndarray:
        """The §8.9 front-face texture: the flat texture modulated by the front-face weight."""
        return self.rgba * self.front_weight[..., None]

    def lookup(self, s_f: Any, s_b: Any, l: Any = 0.0) -> np.ndarray:
        """Bilinear flat RGBA (..., 4) at (s_f, s_b); ``l`` is accepted for a uniform interface and ignored."""
        shape, (sf, sb, _) = _interp.flat_args(s_f, s_b, l)
        out = np.empty((sf.size, 4), dtype=np.float64)
        if sf.size:
            _interp.bilinear(self.rgba, self.s_lo, self.ds, sf, sb, out)
        return out.reshape(shape + (4,))

    def lookup_weight(self, s_f: Any, s_b: Any) -> np.ndarray:
        """Bilinear front-face weight at (s_f, s_b)."""
        shape, (sf, sb) = _interp.flat_args(s_f, s_b)
        out = np.empty((sf.size, 1), dtype=np.float64)
        if sf.size:
            _interp.bilinear(self.front_weight[..., None], self.s_lo, self.ds, sf, sb, out)
        return out.reshape(shape)

    def error(self, width: float | None = None, area: float = 1e4, l: float = 1.0, where: str = "centers",
              **kw: Any) -> TableError:
        """Error of the flat texture against ``integrate_segment`` with the thin-peak TF of ``iso_peaks_tf``.

        Meaningful for opaque isosurfaces with one color per surface (the reference TF cannot express partial
        opacity independent of the segment, nor side-dependent colors). Defaults: peak width ds/8, area 1e4, l = 1.
        """
        width = self.ds / 8 if width is None else width
        tf = iso_peaks_tf(self.isosurfaces, width, area, s_range=(self.s_lo, self.s_hi))
        pts = sample_points(self.s_lo, self.s_hi, l, self.n_s, 1, where, **kw)
        return measure_error(self.lookup, tf, pts, where)


def build_iso_table(isosurfaces: Sequence[IsoSurface | float], n_s: int = 256, s_range: Any = (0.0, 1.0),
                    thicken: float = 0.0) -> IsoTable:
    """Build the flat texture and the smooth-shading weights for one or more isosurfaces (§8.8–8.10)."""
    isos = tuple(i if isinstance(i, IsoSurface) else IsoSurface(float(i)) for i in isosurfaces)
    if not isos:
        raise ValueError("need at least one isosurface")
    if int(n_s) != n_s or n_s < 2:
        raise ValueError(f"n_s must be an integer >= 2, got {n_s}")
    lo, hi = (float(v) for v in s_range)
    if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        raise ValueError(f"s_range must be finite with hi > lo, got {s_range}")
    if not (np.isfinite(thicken) and thicken >= 0):
        raise ValueError(f"thicken must be finite and >= 0, got {thicken}")
    s = np.linspace(lo, hi, n_s)
    sf, sb = np.meshgrid(s, s, indexing="ij")
    ascending = sb >= sf
    rgba = np.zeros((n_s, n_s, 4))
    weight = np.zeros((n_s, n_s))
    trans = np.ones((n_s, n_s))
    found = np.zeros((n_s, n_s), dtype=bool)
    order = sorted(isos, key=lambda i: i.value)
    denom = np.where(sf != sb, sf - sb, 1.0)
    for direction in (True, False):
        seq = order if direction else order[::-1]
        sel = ascending if direction else ~ascending
        for iso in seq:
            h = heaviside_alpha(sf, sb, iso.value, thicken) * sel
            a = h * iso.opacity
            color = np.asarray(iso.color if direction or iso.back_color is None else iso.back_color)
            rgba[..., :3] += (trans * a)[..., None] * color
            rgba[..., 3] += trans * a
            first = (h > 0) & ~found
            weight = np.where(first, np.clip((iso.value - sb) / denom, 0.0, 1.0), weight)
            found |= first
            trans = trans * (1.0 - a)
    weight = np.where(sf == sb, 0.0, weight)
    return IsoTable(rgba.astype(np.float32), weight.astype(np.float32), lo, hi, isos, float(thicken))


def iso_peaks_tf(isosurfaces: Sequence[IsoSurface | float], width: float, area: float,
                 s_range: Any = None) -> TransferFunction:
    """A TF of thin triangular ρ peaks (base ``width``, ∫ρ ds = ``area``) at the isovalues (§8.13's C δ(s − s_iso)).

    A segment crossing one peak gets optical depth area·l/|s_b − s_f|, so α → H·H as area → ∞. Peaks must not
    overlap. ``s_range`` extends the TF with transparent ends (the color is the iso color throughout the peak).
    """
    isos = sorted((i if isinstance(i, IsoSurface) else IsoSurface(float(i)) for i in isosurfaces),
                  key=lambda i: i.value)
    if not (width > 0 and area > 0):
        raise ValueError("peak width and area must be > 0")
    height = 2.0 * area / width
    s: list[float] = []
    c: list[Any] = []
    r: list[float] = []
    for iso in isos:
        if s and iso.value - width / 2 <= s[-1]:
            raise ValueError("isosurface peaks overlap; use a smaller width")
        col = list(iso.color)
        s += [iso.value - width / 2, iso.value, iso.value + width / 2]
        c += [col, col, col]
        r += [0.0, height, 0.0]
    if s_range is not None:
        lo, hi = (float(v) for v in s_range)
        if lo < s[0]:
            s, c, r = [lo] + s, [c[0]] + c, [0.0] + r
        if hi > s[-1]:
            s, c, r = s + [hi], c + [c[-1]], r + [0.0]
    return TransferFunction(s, c, r, name="iso-peaks")

