"""Perlin noise and the scene generators: determinism, lattice zeros, ranges, shapes."""
from __future__ import annotations

import numpy as np

from volviz.nature import noise


def test_perlin_is_zero_on_the_lattice_and_smooth() -> None:
    x = np.arange(-3.0, 4.0)
    assert np.all(noise.perlin3(x, 2.0, -5.0, seed=4) == 0.0)
    a = noise.perlin3(0.3, 0.6, 0.2, seed=4)
    b = noise.perlin3(0.3 + 1e-6, 0.6, 0.2, seed=4)
    assert a != 0.0 and abs(a - b) < 1e-5
    pts = np.random.default_rng(0).uniform(-20, 20, size=(3, 2000))
    v = noise.perlin3(*pts, seed=9)
    assert np.abs(v).max() <= 1.0 and v.std() > 0.1


def test_fbm_is_deterministic_by_seed() -> None:
    a = noise.fbm2((40, 30), seed=3)
    assert np.array_equal(a, noise.fbm2((40, 30), seed=3))
    assert not np.array_equal(a, noise.fbm2((40, 30), seed=4))
    v = noise.fbm3((9, 10, 11), seed=5)
    assert v.shape == (9, 10, 11) and v.dtype == np.float32 and np.array_equal(v, noise.fbm3((9, 10, 11), seed=5))


def test_fbm_scale_is_one_number_for_every_axis_or_one_per_axis() -> None:
    assert np.array_equal(noise.fbm2((20, 30), scale=6.0, seed=1), noise.fbm2((20, 30), scale=(6.0, 6.0), seed=1))
    assert not np.array_equal(noise.fbm2((20, 30), scale=(6.0, 3.0), seed=1), noise.fbm2((20, 30), scale=6.0, seed=1))
    assert np.array_equal(noise.fbm3((9, 10, 11), scale=4, seed=2), noise.fbm3((9, 10, 11), scale=(4, 4, 4), seed=2))


def test_generators_ranges() -> None:
    h = noise.fractal_terrain(65, seed=2, relief=100.0)
    assert h.shape == (65, 65) and h.min() == 0.0 and h.max() == 100.0
    fog = noise.fog_map(h, level=40.0, thickness=10.0, seed=1)
    assert fog.min() >= 0 and fog.max() <= 10.0
    assert np.all(fog[h >= 40.0] == 0.0) and np.any(fog > 0)
    f = noise.cloud_density((33, 33, 17), seed=1, coverage=0.3)
    assert f.min() == 0.0 and f.max() == 1.0
    assert 0.15 < np.mean(f > 0) < 0.5
    assert np.all(f[:, :, 0] == 0) and np.all(f[:, :, -1] == 0)  # the layer thins out at its bottom and top
    g = noise.cloud_light(f, (1.0, 1.0, 1.0), ambient=0.3, diffuse=0.7)
    assert g.min() >= 0.3 - 1e-6 and g.max() <= 1.0 + 1e-6 and g.max() > 0.9
