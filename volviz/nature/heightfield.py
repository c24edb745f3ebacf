"""Height fields on (2^n + 1)^2 grids: the input of the terrain C-LOD (Roettger §3.5.3, digest §2.4).

Convention: ``HeightField.heights[i, j]`` is the elevation at ``x = x0 + i sx`` (east) and ``y = y0 + j sy`` (north),
with ``N = 2^n + 1`` samples per side. Images (``Image2D``: row 0 at the top = north) are turned into this layout by
``grid_from_image``. Grids of other sizes are **resampled** bilinearly to the nearest ``2^n + 1`` at or above their
larger side (default), so the terrain keeps its extent and no sample is lost; the resampling is exact at the original
samples' positions only when the sizes already match, otherwise it is ordinary bilinear interpolation (documented
choice; padding would change the terrain's extent).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

MAX_LEVELS = 14  # 16385^2 samples: refuse larger grids before allocating anything


def pow2_plus_one(n: int) -> int:
    """The smallest 2^k + 1 >= n (k >= 1)."""
    if n < 2:
        raise ValueError(f"a height field needs at least 2 samples per side, got {n}")
    k = max(1, int(np.ceil(np.log2(n - 1))))
    if k > MAX_LEVELS:
        raise ValueError(f"height field side {n} exceeds the supported 2^{MAX_LEVELS} + 1 samples")
    return (1 << k) + 1


def is_pow2_plus_one(n: int) -> bool:
    return n >= 3 and ((n - 1) & (n - 2)) == 0


def resample_bilinear(values: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Bilinear resampling of a 2D array so that the corner samples stay at the corners (align-corners)."""
    a = np.asarray(values, dtype=np.float64)
    if a.ndim != 2:
        raise ValueError(f"expected a 2D array, got shape {a.shape}")
    if a.shape == tuple(shape):
        return a.copy()
    out = a
    for axis, n_new in enumerate(shape):
        n_old = out.shape[axis]
        if n_old == n_new:
            continue
        pos = np.linspace(0.0, n_old - 1.0, n_new)
        i0 = np.clip(np.floor(pos).astype(np.int64), 0, max(n_old - 2, 0))
        frac = pos - i0
        i1 = np.minimum(i0 + 1, n_old - 1)
        lo = np.take(out, i0, axis=axis)
        hi = np.take(out, i1, axis=axis)
        shape_f = [1, 1]
        shape_f[axis] = n_new
        frac = frac.reshape(shape_f)
        out = lo * (1.0 - frac) + hi * frac
    return out


def grid_from_image(data: np.ndarray) -> np.ndarray:
    """An image array (rows, cols), row 0 north, as the x-major grid ``g[i, j]`` (i east, j north)."""
    a = np.asarray(data)
    if a.ndim == 3:
        a = a[..., 0]
    return np.ascontiguousarray(a[::-1, :].T)


@dataclass
class HeightField:
    """Elevations on a (2^n + 1)^2 grid, ``heights[i, j]`` at (x0 + i sx, y0 + j sy)."""

    heights: np.ndarray
    spacing: tuple[float, float] = (1.0, 1.0)
    origin: tuple[float, float] = (0.0, 0.0)
    source: str = ""

    def __post_init__(self) -> None:
        h = np.ascontiguousarray(self.heights, dtype=np.float64)
        if h.ndim != 2 or h.shape[0] != h.shape[1] or not is_pow2_plus_one(h.shape[0]):
            raise ValueError(f"HeightField needs a (2^n + 1)^2 grid, got shape {h.shape}; use HeightField.from_array")
        if not np.all(np.isfinite(h)):
            raise ValueError("HeightField heights must be finite")
        sx, sy = (float(v) for v in self.spacing)
        if not (sx > 0 and sy > 0 and np.isfinite(sx) and np.isfinite(sy)):
            raise ValueError(f"HeightField spacing must be positive, got {self.spacing}")
        self.heights = h
        self.spacing = (sx, sy)
        self.origin = (float(self.origin[0]), float(self.origin[1]))

    @property
    def size(self) -> int:
        return int(self.heights.shape[0])

    @property
    def extent(self) -> tuple[float, float]:
        return ((self.size - 1) * self.spacing[0], (self.size - 1) * self.spacing[1])

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        ex, ey = self.extent
        return (self.origin[0], self.origin[0] + ex, self.origin[1], self.origin[1] + ey,
                float(self.heights.min()), float(self.heights.max()))

    def world_xy(self) -> tuple[np.ndarray, np.ndarray]:
        n = self.size
        return (self.origin[0] + np.arange(n) * self.spacing[0], self.origin[1] + np.arange(n) * self.spacing[1])

    def height_at(self, x: float, y: float) -> float:
        """Bilinearly interpolated terrain height at world (x, y), clamped to the grid (fly-through collision)."""
        n = self.size
        u = min(max((x - self.origin[0]) / self.spacing[0], 0.0), n - 1.0)
        v = min(max((y - self.origin[1]) / self.spacing[1], 0.0), n - 1.0)
        i, j = min(int(u), n - 2), min(int(v), n - 2)
        fu, fv = u - i, v - j
        h = self.heights
        return float((1 - fu) * ((1 - fv) * h[i, j] + fv * h[i, j + 1])
                     + fu * ((1 - fv) * h[i + 1, j] + fv * h[i + 1, j + 1]))

    def sample(self, grid: np.ndarray) -> np.ndarray:
        """Resample another x-major grid (e.g. a fog map) to this height field's (N, N) samples."""
        return resample_bilinear(grid, (self.size, self.size))

    def normals(self) -> np.ndarray:
        """Unit normals (N, N, 3) from central differences of the full-resolution heights."""
        h = self.heights
        gx = np.gradient(h, self.spacing[0], axis=0)
        gy = np.gradient(h, self.spacing[1], axis=1)
        n = np.stack([-gx, -gy, np.ones_like(h)], axis=-1)
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    @classmethod
    def from_array(cls, grid: np.ndarray, extent: tuple[float, float], height_scale: float = 1.0,
                   origin: tuple[float, float] = (0.0, 0.0), size: int | None = None,
                   source: str = "") -> "HeightField":
        """From an x-major grid of any size: resampled to ``size`` (default: the next 2^n + 1) over ``extent``."""
        g = np.asarray(grid, dtype=np.float64)
        if g.ndim != 2:
            raise ValueError(f"height grid must be 2D, got shape {g.shape}")
        n = pow2_plus_one(max(g.shape)) if size is None else int(size)
        if not is_pow2_plus_one(n):
            raise ValueError(f"height field size must be 2^k + 1, got {n}")
        ex, ey = (float(v) for v in extent)
        h = resample_bilinear(g, (n, n)) * float(height_scale)
        return cls(h, (ex / (n - 1), ey / (n - 1)), origin, source)

    @classmethod
    def from_image(cls, image: Any, extent: tuple[float, float] | None = None, height_scale: float = 1.0,
                   size: int | None = None) -> "HeightField":
        """From an ``Image2D`` (PGM map or DEM): row 0 is north. ``extent`` defaults to the image's own spacing."""
        data = np.asarray(image.data)
        if data.ndim == 3:
            data = data[..., 0]
        rows, cols = data.shape
        if extent is None:
            extent = ((cols - 1) * image.spacing[0], (rows - 1) * image.spacing[1])
        origin = tuple(getattr(image, "origin", (0.0, 0.0)))
        return cls.from_array(grid_from_image(data), extent, height_scale, origin, size,
                              source=getattr(image, "source", ""))
