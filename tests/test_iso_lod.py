"""View-dependent isosurface LOD with geomorphing (libMini note, "4D Visualization")."""
from __future__ import annotations

import numpy as np

from volviz.iso.composite import render
from volviz.iso.extract import IsoStyle, extract
from volviz.iso.lod import build_lod, lod_mesh, lod_meshes, select_level
from volviz.model.datasets import RegularVolume
from volviz.optics.metrics import rmse
from volviz.model.camera import Camera


def _chain():
    x = np.linspace(-1, 1, 33)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    f = 1 - np.sqrt(X * X + Y * Y + Z * Z) + 0.05 * np.sin(6 * X)
    v = RegularVolume(data=f.astype(np.float32), spacing=(2 / 32,) * 3, origin=(-1.0,) * 3)
    (m,) = extract(v, [IsoStyle(0.4, (0.2, 0.8, 0.3), 0.5)])
    return build_lod(m, n_levels=4)


def test_levels_shrink_and_far_views_draw_fewer_triangles():
    ch = _chain()
    counts = ch.triangle_counts
    assert len(counts) == 4 and all(a > 1.8 * b for a, b in zip(counts, counts[1:]))
    drawn = []
    for d in (1.2, 4.0, 16.0, 64.0):
        cam = Camera.orbit(ch.levels[0].points, distance=d)
        drawn.append(lod_meshes([ch], cam, (128, 128))[0].n_triangles)
    assert drawn[0] == counts[0] and drawn[-1] == counts[-1]
    assert all(a >= b for a, b in zip(drawn, drawn[1:])) and drawn[0] > drawn[-1]


def test_geomorph_meets_the_next_level_and_is_continuous():
    ch = _chain()
    for k in range(len(ch.levels) - 1):
        end = lod_mesh(ch, k + 1 - 1e-12)
        # every morphed vertex sits on a vertex of the next level; the geometry it shows is that level's
        np.testing.assert_allclose(end.points, ch.levels[k + 1].points[ch.parent[k]], atol=1e-9)
        a, b = lod_mesh(ch, k + 0.5), lod_mesh(ch, k + 0.5 + 1e-3)
        assert np.max(np.abs(a.points - b.points)) < 1e-3 * 2 * ch.radius
    cam = Camera.orbit(ch.levels[0].points, distance=3.0)
    lvl = lambda lam: render([lod_mesh(ch, lam)], cam, (96, 96))[0]  # noqa: E731
    pop_morph = rmse(lvl(1 - 1e-9), lvl(1.0))
    pop_plain = rmse(lvl(0.0), lvl(1.0))
    assert pop_morph < 0.5 * pop_plain
    assert 0.0 <= select_level(ch, cam, (96, 96)) <= 3.0
