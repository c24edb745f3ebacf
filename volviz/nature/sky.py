"""Sky dome (Roettger §5.1): a tessellated hemisphere textured with a sky photo resampled in polar coordinates.

The texture (e.g. ``SkyDome.ppm``, 2048 x 512) is already in polar form: columns are the azimuth (u = azimuth / 2π,
measured counter-clockwise from +x), rows the elevation with the zenith at the top edge and the horizon at the bottom
edge. The dome mesh carries texture coordinates (u, v) with v = elevation / (π/2), i.e. v = 1 at the zenith = the
top row of the image (``pyvista.Texture`` of a NumPy image puts row 0 at v = 1). A seam column is duplicated so u
runs 0 → 1 without wrapping. ``volviz.nature.raster.render_sky`` evaluates the same mapping per pixel for the CPU
frames (the dome at infinity, valid while the viewer moves little compared with the dome's radius).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np


def sky_dome_mesh(radius: float, centre: Sequence[float] = (0.0, 0.0, 0.0), n_azimuth: int = 64,
                  n_elevation: int = 16, skirt: float = 0.5 * np.pi) -> Any:
    """A hemisphere (plus a short skirt ``skirt`` radians below the horizon, colored like the horizon) as
    ``pyvista.PolyData`` with texture coordinates; normals point inwards (seen from inside)."""
    # PyVista (VTK, heavy): only where the sky dome is drawn by VTK
    import pyvista as pv

    if not radius > 0:
        raise ValueError(f"sky dome radius must be positive, got {radius}")
    if n_azimuth < 3 or n_elevation < 2:
        raise ValueError("sky dome needs at least 3 azimuth and 2 elevation steps")
    az = np.linspace(0.0, 2.0 * np.pi, n_azimuth + 1)
    el = np.concatenate([[-abs(skirt)], np.linspace(0.0, 0.5 * np.pi, n_elevation + 1)])
    A, E = np.meshgrid(az, el, indexing="ij")
    c = np.asarray(centre, dtype=np.float64)
    pts = np.stack([c[0] + radius * np.cos(E) * np.cos(A), c[1] + radius * np.cos(E) * np.sin(A),
                    c[2] + radius * np.sin(E)], axis=-1).reshape(-1, 3)
    tc = np.stack([A / (2.0 * np.pi), np.clip(E, 0.0, None) / (0.5 * np.pi)], axis=-1).reshape(-1, 2)
    ne = len(el)
    quads = []
    for i in range(n_azimuth):
        for j in range(ne - 1):
            a, b = i * ne + j, (i + 1) * ne + j
            quads.append([4, a, a + 1, b + 1, b])  # inward-facing winding
    mesh = pv.PolyData(pts, np.asarray(quads, dtype=np.int64).ravel())
    # pyvista types the setter's array as float64 only; VTK takes float32 texture coordinates
    mesh.active_texture_coordinates = tc.astype(np.float32)  # type: ignore[assignment]
    return mesh


def sky_texture(image: Any) -> np.ndarray:
    """An ``Image2D`` (PPM, rows, cols, 3) or array as float32 RGB in [0, 1] (row 0 = zenith)."""
    data = np.asarray(getattr(image, "data", image))
    if data.ndim != 3 or data.shape[2] < 3:
        raise ValueError(f"sky texture must be an RGB image, got shape {data.shape}")
    maxval = float(getattr(image, "maxval", None) or (255 if data.dtype == np.uint8 else data.max() or 1.0))
    return np.ascontiguousarray(data[..., :3].astype(np.float32) / maxval)
