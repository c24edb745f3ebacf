"""Isosurfaces through projected tetrahedra (Roettger §8.8-8.10, §8.13): every ray segment (s_f, s_b) of a cell
looks up the flat isosurface texture of ``volviz.optics.isosurface`` (independent of the length l), so several
coloured, semi-transparent isosurfaces are drawn by the same rasteriser and compositing as the volume.

- ``iso_lut``: the (n, n) texture as an l-independent "3D table" (two identical l slices) for ``raster.lut_args``;
  bilinear filtering of the discontinuous texture blurs a surface over about one texel of (s_f, s_b), i.e. pixels
  whose segment ends within ds of the isovalue are partly covered (the §8.8 behaviour of texture filtering).
- ``iso_segment_rgba``: the exact flat colour of segments (the §8.13 Heaviside limit with H(0) = 1/2, surfaces
  composited in ray order, side-dependent colours), used by the "reference" method.
- ``iso_visible``: cells whose scalar range meets an isovalue (± thicken); the others cannot show a surface.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.unstructured.topology import cell_ranges


@dataclass
class IsoLUT:
    """An l-independent table with the layout of ``Table3D`` (rgba (n, n, 2, 4) float32)."""

    rgba: np.ndarray
    s_lo: float
    ds: float
    dl: float = 1.0


def iso_lut(table: Any) -> IsoLUT:
    """The flat texture of an ``IsoTable`` as a two-slice 3D table."""
    flat = np.asarray(table.rgba, dtype=np.float32)
    return IsoLUT(np.ascontiguousarray(np.stack([flat, flat], axis=2)), float(table.s_lo), float(table.ds))


def iso_visible(mesh: TetMesh, table: Any) -> np.ndarray:
    """Boolean mask of cells whose [min, max] scalar range meets some isovalue widened by ``thicken``."""
    r = cell_ranges(mesh)
    vis = np.zeros(len(r.smin), dtype=bool)
    for iso in table.isosurfaces:
        vis |= (r.smin <= iso.value + table.thicken) & (r.smax >= iso.value - table.thicken)
    return vis & ~r.nan


def iso_segment_rgba(table: Any, s_f: np.ndarray, s_b: np.ndarray) -> np.ndarray:
    """Exact premultiplied flat RGBA (k, 4) of segments: the isosurfaces crossed between s_f and s_b, front to back
    (increasing values when s_f < s_b, decreasing otherwise), each with its opacity and side colour."""
    from volviz.optics.isosurface import heaviside_alpha

    sf = np.asarray(s_f, dtype=np.float64)
    sb = np.asarray(s_b, dtype=np.float64)
    out = np.zeros(sf.shape + (4,))
    trans = np.ones(sf.shape)
    order = sorted(table.isosurfaces, key=lambda i: i.value)
    for ascending in (True, False):
        sel = (sb >= sf) if ascending else (sb < sf)
        for iso in (order if ascending else order[::-1]):
            a = heaviside_alpha(sf, sb, iso.value, table.thicken) * sel * iso.opacity
            colour = np.asarray(iso.color if ascending or iso.back_color is None else iso.back_color)
            out[..., :3] += (trans * a)[..., None] * colour
            out[..., 3] += trans * a
            trans = trans * (1.0 - a)
    return out
