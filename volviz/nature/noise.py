"""Perlin gradient noise and fractal sums: terrain, ground-fog maps and cloud densities (Roettger §10.4, §11.6.2, [82]).

``perlin2``/``perlin3`` are Perlin's improved gradient noise (quintic fade 6t^5 - 15t^4 + 10t^3, gradients picked by a
seeded permutation), zero at every integer lattice point and within about [-1, 1]. ``fbm2``/``fbm3`` sum ``octaves``
of it with ``lacunarity`` (frequency factor) and ``persistence`` (amplitude factor), normalised by the sum of the
amplitudes. Everything is deterministic for a given seed (NumPy's PCG64 builds the permutation) and runs in Numba,
in parallel over the first axis.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

_GRAD3 = np.array([[1, 1, 0], [-1, 1, 0], [1, -1, 0], [-1, -1, 0], [1, 0, 1], [-1, 0, 1], [1, 0, -1], [-1, 0, -1],
                   [0, 1, 1], [0, -1, 1], [0, 1, -1], [0, -1, -1], [1, 1, 0], [-1, 1, 0], [0, -1, 1], [0, -1, -1]],
                  dtype=np.float64)
_GRAD2 = np.array([[1, 1], [-1, 1], [1, -1], [-1, -1], [1, 0], [-1, 0], [0, 1], [0, -1]], dtype=np.float64) / 1.0


def permutation(seed: int) -> np.ndarray:
    """A seeded permutation of 0..255, doubled to 512 entries (no index wrapping needed)."""
    p = np.random.default_rng(int(seed)).permutation(256).astype(np.int64)
    return np.concatenate([p, p])


@njit(cache=True, nogil=True, inline="always")
def _fade(t: float) -> float:
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@njit(cache=True, nogil=True)
def perlin3_at(perm: np.ndarray, grad: np.ndarray, x: float, y: float, z: float) -> float:
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    xi, yi, zi = int(fx) & 255, int(fy) & 255, int(fz) & 255
    x -= fx
    y -= fy
    z -= fz
    u, v, w = _fade(x), _fade(y), _fade(z)
    acc = 0.0
    for c in range(8):
        dx, dy, dz = c & 1, (c >> 1) & 1, (c >> 2) & 1
        g = perm[perm[perm[xi + dx] + yi + dy] + zi + dz] & 15
        dot = grad[g, 0] * (x - dx) + grad[g, 1] * (y - dy) + grad[g, 2] * (z - dz)
        wx = u if dx else 1.0 - u
        wy = v if dy else 1.0 - v
        wz = w if dz else 1.0 - w
        acc += wx * wy * wz * dot
    return acc


@njit(cache=True, nogil=True)
def perlin2_at(perm: np.ndarray, grad: np.ndarray, x: float, y: float) -> float:
    fx, fy = math.floor(x), math.floor(y)
    xi, yi = int(fx) & 255, int(fy) & 255
    x -= fx
    y -= fy
    u, v = _fade(x), _fade(y)
    acc = 0.0
    for c in range(4):
        dx, dy = c & 1, (c >> 1) & 1
        g = perm[perm[xi + dx] + yi + dy] & 7
        dot = grad[g, 0] * (x - dx) + grad[g, 1] * (y - dy)
        acc += (u if dx else 1.0 - u) * (v if dy else 1.0 - v) * dot
    return acc


@njit(cache=True, nogil=True, parallel=True)
def _fbm3_grid(perm, grad, nx, ny, nz, fx, fy, fz, ox, oy, oz, octaves, lacunarity, persistence, out):
    norm = (1.0 - persistence ** octaves) / (1.0 - persistence) if persistence != 1.0 else float(octaves)
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                x, y, z = ox + i * fx, oy + j * fy, oz + k * fz
                amp, f, s = 1.0, 1.0, 0.0
                for o in range(octaves):
                    s += amp * perlin3_at(perm, grad, x * f + 17.3 * o, y * f + 5.1 * o, z * f + 31.7 * o)
                    amp *= persistence
                    f *= lacunarity
                out[i, j, k] = s / norm


@njit(cache=True, nogil=True, parallel=True)
def _fbm2_grid(perm, grad, nx, ny, fx, fy, ox, oy, octaves, lacunarity, persistence, out):
    norm = (1.0 - persistence ** octaves) / (1.0 - persistence) if persistence != 1.0 else float(octaves)
    for i in prange(nx):
        for j in range(ny):
            x, y = ox + i * fx, oy + j * fy
            amp, f, s = 1.0, 1.0, 0.0
            for o in range(octaves):
                s += amp * perlin2_at(perm, grad, x * f + 17.3 * o, y * f + 5.1 * o)
                amp *= persistence
                f *= lacunarity
            out[i, j] = s / norm


def perlin3(x: np.ndarray, y: np.ndarray, z: np.ndarray, seed: int = 0) -> np.ndarray:
    """Improved Perlin noise at arbitrary points (vectorised over the broadcast shape)."""
    perm = permutation(seed)
    bx, by, bz = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(z, float))
    out = np.empty(bx.shape)
    fo, fx_, fy_, fz_ = out.reshape(-1), bx.reshape(-1), by.reshape(-1), bz.reshape(-1)
    for i in range(fo.size):
        fo[i] = perlin3_at(perm, _GRAD3, fx_[i], fy_[i], fz_[i])
    return out


def _per_axis(scale: float | tuple[float, ...], n: int) -> list[float]:
    """``scale`` for each of ``n`` axes: one number for all of them, or one per axis."""
    return [float(v) for v in np.broadcast_to(np.asarray(scale, dtype=np.float64), (n,))]


def fbm2(shape: tuple[int, int], scale: float | tuple[float, float] = 8.0, octaves: int = 5, lacunarity: float = 2.0,
         persistence: float = 0.5, seed: int = 0, offset: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """2D fractal Brownian motion on a grid: ``scale`` lattice cells of the base octave across each axis."""
    nx, ny = (int(v) for v in shape)
    sx, sy = _per_axis(scale, 2)
    out = np.empty((nx, ny))
    _fbm2_grid(permutation(seed), _GRAD2, nx, ny, float(sx) / max(nx - 1, 1), float(sy) / max(ny - 1, 1),
               float(offset[0]), float(offset[1]), int(octaves), float(lacunarity), float(persistence), out)
    return out


def fbm3(shape: tuple[int, int, int], scale: float | tuple[float, float, float] = 8.0, octaves: int = 5,
         lacunarity: float = 2.0, persistence: float = 0.5, seed: int = 0,
         offset: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """3D fractal Brownian motion on a grid (Roettger's cloud and camp-fire generator, [82])."""
    nx, ny, nz = (int(v) for v in shape)
    sx, sy, sz = _per_axis(scale, 3)
    out = np.empty((nx, ny, nz), dtype=np.float32)
    _fbm3_grid(permutation(seed), _GRAD3, nx, ny, nz, float(sx) / max(nx - 1, 1), float(sy) / max(ny - 1, 1),
               float(sz) / max(nz - 1, 1), float(offset[0]), float(offset[1]), float(offset[2]), int(octaves),
               float(lacunarity), float(persistence), out)
    return out


# ------------------------------------------------------------------------------------------------------ generators
def fractal_terrain(n: int = 257, seed: int = 1, relief: float = 1.0, octaves: int = 8) -> np.ndarray:
    """An (n, n) fractal height field in [0, relief]: fBm shaped to flat valleys and sharper peaks."""
    h = fbm2((n, n), scale=4.0, octaves=octaves, persistence=0.5, seed=seed)
    h = (h - h.min()) / max(float(np.ptp(h)), 1e-12)
    return relief * h ** 1.6


def fog_map(heights: np.ndarray, level: float, thickness: float, seed: int = 2, patchiness: float = 0.6) -> np.ndarray:
    """Ground-fog thickness above the ground (§10.4): fills valleys below ``level`` and is modulated by 2D Perlin
    noise; at most ``thickness``, zero on ridges above the level and in the noise's gaps."""
    n0, n1 = heights.shape
    noise = fbm2((n0, n1), scale=6.0, octaves=4, seed=seed)
    noise = (noise - noise.min()) / max(float(np.ptp(noise)), 1e-12)
    mask = np.clip((noise - (1.0 - patchiness)) / max(patchiness, 1e-6) * 2.0, 0.0, 1.0)
    valley = np.clip(level - heights, 0.0, None)
    return np.minimum(valley, thickness) * mask


def cloud_density(shape: tuple[int, int, int], seed: int = 3, coverage: float = 0.3, scale: float = 6.0,
                  octaves: int = 5, sharpness: float = 3.0, edge: str = "hard") -> np.ndarray:
    """Cumulus-like density f in [0, 1] on a (nx, ny, nz) grid, float32 (§11.6.2: 3D Perlin noise).

    fBm with ``scale`` base cells across x and y (z scaled to keep cells cubic), a vertical profile that thins the
    cloud towards the layer's top and bottom and flattens the bases, then ``f = clip((noise - threshold) sharpness, 0,
    1)`` with the threshold chosen so that roughly ``coverage`` of the samples are non-zero.

    ``edge="smooth"`` band-limits the result for the LOD (§11.3: a piecewise-linear octree can only represent what
    its cells resolve): the clip becomes a smoothstep 3x^2 - 2x^3 (C1 at the cloud's edge and core instead of two
    kinks) and the vertical profile a smoothstep ramp. Use few octaves (2 at scale 4 on a 513-point grid keeps every
    octave above 60 samples per period).
    """
    if edge not in ("hard", "smooth"):
        raise ValueError(f"edge must be 'hard' or 'smooth', got {edge!r}")
    nx, ny, nz = (int(v) for v in shape)
    sz = scale * (nz - 1) / max(nx - 1, 1)
    f = fbm3((nx, ny, nz), scale=(scale, scale * (ny - 1) / max(nx - 1, 1), sz), octaves=octaves, seed=seed)
    zeta = np.linspace(0.0, 1.0, nz, dtype=np.float32)
    if edge == "smooth":
        profile = np.clip(np.minimum(zeta / 0.35, (1.0 - zeta) / 0.6), 0.0, 1.0)
        profile = profile * profile * (3.0 - 2.0 * profile)
    else:
        profile = np.clip(np.minimum(zeta / 0.25, (1.0 - zeta) / 0.6), 0.0, 1.0) ** 0.5
    f = f * np.float32(0.5) + np.float32(0.5) * profile[None, None, :] - np.float32(0.25)
    sample = f[:: max(nx // 64, 1), :: max(ny // 64, 1), :]
    threshold = float(np.quantile(sample, 1.0 - coverage))
    f -= np.float32(threshold)
    f *= np.float32(sharpness / max(float(sample.max()) - threshold, 1e-6))
    np.clip(f, 0.0, 1.0, out=f)
    if edge == "smooth":
        f *= f * (np.float32(3.0) - np.float32(2.0) * f)
    return f


@njit(cache=True, nogil=True, parallel=True)
def _light(f, sx, sy, sz, lx, ly, lz, ambient, diffuse, g0, out):
    nx, ny, nz = f.shape
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                i0, i1 = max(i - 1, 0), min(i + 1, nx - 1)
                j0, j1 = max(j - 1, 0), min(j + 1, ny - 1)
                k0, k1 = max(k - 1, 0), min(k + 1, nz - 1)
                gx = (f[i1, j, k] - f[i0, j, k]) / ((i1 - i0) * sx)
                gy = (f[i, j1, k] - f[i, j0, k]) / ((j1 - j0) * sy)
                gz = (f[i, j, k1] - f[i, j, k0]) / ((k1 - k0) * sz)
                g = math.sqrt(gx * gx + gy * gy + gz * gz + g0 * g0)
                lam = 0.0
                if g > 1e-12:
                    lam = -(gx * lx + gy * ly + gz * lz) / g  # outward normal = -grad f
                out[i, j, k] = ambient + diffuse * max(lam, 0.0)


def cloud_light(density: np.ndarray, spacing: tuple[float, float, float], light_dir=(0.4, 0.3, 0.85),
                ambient: float = 0.35, diffuse: float = 0.65, soft: float = 0.0) -> np.ndarray:
    """Isotropic light intensity gamma = ambient + diffuse max(n . L, 0), n = -grad f / |grad f| (§11.6.2; the thesis
    leaves the normal's source open, the density gradient is the natural choice). float32, in [ambient, ambient +
    diffuse].

    ``soft`` > 0 normalises by sqrt(|grad f|^2 + g0^2), g0 = ``soft`` x the median gradient magnitude inside the
    cloud (f > 0.05): where the gradient vanishes (flat cores, the empty sky, saddles) the unit normal flips
    arbitrarily and gamma jumps between neighbouring samples; the soft form fades to the ambient term there instead,
    so gamma is as smooth as f and the LOD need not resolve spurious light edges."""
    L = np.asarray(light_dir, dtype=np.float64)
    L = L / np.linalg.norm(L)
    out = np.empty(density.shape, dtype=np.float32)
    g0 = 0.0
    if soft > 0:
        f = np.asarray(density, dtype=np.float64)
        step = max(1, int(round((f.size / 2e6) ** (1 / 3))))  # a subsample suffices for a median
        sub = f[::step, ::step, ::step]
        grads = np.gradient(sub, *(float(s) * step for s in spacing))
        mag = np.sqrt(sum(gr * gr for gr in grads))[sub > 0.05]
        g0 = float(soft) * (float(np.median(mag)) if mag.size else 0.0)
    _light(np.ascontiguousarray(density), float(spacing[0]), float(spacing[1]), float(spacing[2]),
           L[0], L[1], L[2], float(ambient), float(diffuse), g0, out)
    return out
