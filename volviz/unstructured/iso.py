"""Isosurfaces through projected tetrahedra (Roettger §8.8-8.10, §8.13): every ray segment (s_f, s_b) of a cell
looks up the flat isosurface texture of ``volviz.optics.isosurface`` (independent of the length l), so several
colored, semi-transparent isosurfaces are drawn by the same rasteriser and compositing as the volume.

- ``iso_lut``: the (n, n) texture as an l-independent "3D table" (two identical l slices) for ``raster.lut_args``;
  bilinear filtering of the discontinuous texture blurs a surface over about one texel of (s_f, s_b), i.e. pixels
  whose segment ends within ds of the isovalue are partly covered (the §8.8 behaviour of texture filtering).
- ``iso_segment_rgba``: the exact flat color of segments (the §8.13 Heaviside limit with H(0) = 1/2, surfaces
  composited in ray order, side-dependent colors), used by the "reference" method.
- ``iso_visible``: cells whose scalar range meets an isovalue (± thicken); the others cannot show a surface.
- ``vertex_shade``: smooth shading (§8.9). Every vertex gets a diffuse intensity from its normal (the volume-weighted
  mean of the scalar gradients of its cells) and a headlight; the intensity is interpolated linearly inside each
  cell like the scalar, so along a segment it is linear from its front value h_f to its back value h_b, and a
  surface crossed at s_iso is shaded h_f + w (h_b - h_f) with w = (s_iso - s_f)/(s_b - s_f): the thesis's blend of
  the shaded front- and back-face triangles with the weight texture (s_iso - s_b)/(s_f - s_b) for the front face,
  evaluated exactly per pixel instead of through a texture.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.model.object_cache import ObjectCache
from volviz.optics.isosurface import heaviside_alpha
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


#: per mesh while it lives: its vertex normals (``vertex_normals``)
_NORMALS: ObjectCache[np.ndarray] = ObjectCache()


def vertex_normals(mesh: TetMesh) -> np.ndarray:
    """Unit vertex normals (n, 3): the volume-weighted mean scalar gradient of the incident cells (zero where the
    field is flat or undefined). Kept for the mesh while it lives."""
    cached = _NORMALS.get(mesh)
    if cached is not None:
        return cached
    p = mesh.points[mesh.tets]                                       # (m, 4, 3)
    e = p[:, 1:] - p[:, :1]                                          # (m, 3, 3) edge vectors
    s = mesh.scalars[mesh.tets]
    ds = s[:, 1:] - s[:, :1]
    vol = np.abs(np.linalg.det(e))
    ok = (vol > 1e-300) & np.all(np.isfinite(ds), axis=1)
    grad = np.zeros((len(e), 3))
    grad[ok] = np.linalg.solve(e[ok], ds[ok][..., None])[..., 0]
    acc = np.zeros((len(mesh.points), 3))
    for v in range(4):
        np.add.at(acc, mesh.tets[:, v], grad * vol[:, None])
    norm = np.linalg.norm(acc, axis=1, keepdims=True)
    out = np.divide(acc, norm, out=np.zeros_like(acc), where=norm > 0)
    return _NORMALS.put(mesh, out)


def vertex_shade(mesh: TetMesh, light: np.ndarray, ambient: float = 0.3) -> np.ndarray:
    """Per-vertex intensity ambient + (1 - ambient) |n . light| (two-sided diffuse; 1 where there is no normal)."""
    n = vertex_normals(mesh)
    lv = np.asarray(light, dtype=np.float64)
    lv = lv / np.linalg.norm(lv)
    d = np.abs(n @ lv)
    d[~np.any(n != 0.0, axis=1)] = 1.0
    return ambient + (1.0 - ambient) * d


def iso_segment_rgba(table: Any, s_f: np.ndarray, s_b: np.ndarray, h_f: np.ndarray | None = None,
                     h_b: np.ndarray | None = None) -> np.ndarray:
    """Exact premultiplied RGBA (k, 4) of segments: the isosurfaces crossed between s_f and s_b, front to back
    (increasing values when s_f < s_b, decreasing otherwise), each with its opacity and side color; with shading
    intensities ``h_f``/``h_b`` at the segment's ends each surface's color is scaled by the intensity where it is
    crossed (smooth shading; see the module docstring), else flat."""
    sf = np.asarray(s_f, dtype=np.float64)
    sb = np.asarray(s_b, dtype=np.float64)
    smooth = h_f is not None and h_b is not None
    if smooth:
        hf = np.asarray(h_f, dtype=np.float64)
        hb = np.asarray(h_b, dtype=np.float64)
        span = sb - sf
        safe = np.where(span != 0.0, span, 1.0)
    out = np.zeros(sf.shape + (4,))
    trans = np.ones(sf.shape)
    order = sorted(table.isosurfaces, key=lambda i: i.value)
    for ascending in (True, False):
        sel = (sb >= sf) if ascending else (sb < sf)
        for iso in (order if ascending else order[::-1]):
            a = heaviside_alpha(sf, sb, iso.value, table.thicken) * sel * iso.opacity
            color = np.asarray(iso.color if ascending or iso.back_color is None else iso.back_color)
            if smooth:
                w = np.where(span != 0.0, np.clip((iso.value - sf) / safe, 0.0, 1.0), 0.5)
                color = color * (hf + w * (hb - hf))[..., None]
            out[..., :3] += (trans * a)[..., None] * color
            out[..., 3] += trans * a
            trans = trans * (1.0 - a)
    return out
