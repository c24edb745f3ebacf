"""Isosurfaces through projected tetrahedra (Roettger §8.8-8.10, §8.13): several colored, semi-transparent surfaces
with side-dependent colors, "pt" (exact Heaviside per pixel segment, or the bilinear texture) against the
"reference" (the Heaviside limit on exact ray segments)."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.datasets import TetMesh
from volviz.optics.isosurface import IsoSurface, build_iso_table
from volviz.unstructured import synthetic as syn
from volviz.model.camera import Camera
from volviz.unstructured.render import render

SIZE = (48, 40)
ISO = build_iso_table([IsoSurface(0.3, (1.0, 0.2, 0.1), 0.6, back_color=(0.2, 1.0, 0.2)),
                       IsoSurface(0.55, (0.1, 0.3, 1.0), 0.8)], n_s=512, s_range=(0.0, 0.9))


def test_reference_isosurface_closed_form():
    """s = x on the unit right tetrahedron. Seen along z, s is constant along every ray: no surface is crossed.
    Seen along +x, a ray at (y, z) runs from x = 0 to x = 1 - y - z and crosses s = 0.3 (and 0.55) iff its exit is
    beyond it: exact opacities 0.6 and 1 - 0.4 x 0.2 and the composited front colors."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    m = TetMesh(pts, np.array([[0, 1, 2, 3]]), pts[:, 0].copy())
    along_z = Camera((0.5, 0.5, 5.0), (0.5, 0.5, 0.0), (0, 1, 0), parallel=True, parallel_scale=0.5,
                     clipping_range=(0.1, 10))
    assert render(m, None, along_z, (16, 16), "reference", iso=ISO)[..., 3].max() == 0.0
    along_x = Camera((-5.0, 0.5, 0.5), (0.5, 0.5, 0.5), (0, 0, 1), parallel=True, parallel_scale=0.5,
                     clipping_range=(0.1, 10))
    img = render(m, None, along_x, (16, 16), "reference", iso=ISO)
    col, row = np.meshgrid(np.arange(16), np.arange(16))
    y, z = 1.0 - (col + 0.5) / 16, 1.0 - (row + 0.5) / 16               # the camera's right is -y
    exit_x = 1.0 - y - z                                                  # the ray enters at x = 0
    hit, second = exit_x > 0.3, exit_x > 0.55
    one = hit & ~second
    # seen from the low side (s increasing along the ray): the first surface's front color with its opacity
    assert np.allclose(img[one, 3], 0.6) and np.allclose(img[one, :3], 0.6 * np.array([1.0, 0.2, 0.1]))
    assert np.allclose(img[second, 3], 1 - 0.4 * 0.2)
    assert np.allclose(img[second, :3], 0.6 * np.array([1.0, 0.2, 0.1]) + 0.4 * 0.8 * np.array([0.1, 0.3, 1.0]))
    assert np.all(img[~hit, 3] == 0.0) and one.sum() > 30 and second.sum() > 10


@pytest.mark.parametrize("inside", [False, True], ids=["outside", "camera-inside"])
def test_pt_exact_isosurfaces_match_reference(inside):
    m = syn.box_tets(8, jitter=0.2)                                        # s = distance from the centre
    cam = (Camera((0.45, 0.55, 0.5), (1.0, 0.8, 0.6), (0, 0, 1), 70.0, clipping_range=(0.05, 10.0)) if inside
           else Camera.orbit(m.points, 30, 20, 2.5))
    ref = render(m, None, cam, SIZE, "reference", iso=ISO)
    img, st = render(m, None, cam, SIZE, "pt", iso=ISO, return_stats=True)
    assert st.n_visible < m.n_cells                                      # cells without a surface are culled
    assert ref[..., 3].mean() > 0.3
    assert np.abs(img - ref).max() * 255 < 0.01                           # float32 isovalues only
    green = (ref[..., 1] > ref[..., 0] + 0.1)                             # s = 0.3 seen from its high side
    assert (green.sum() > 50) != inside                                   # from inside only the low side shows


def test_pt_texture_isosurfaces_are_close():
    """The GPU-style bilinear texture (Roettger §8.8): pixels whose segment ends within a texel of an isovalue are
    partly covered; overall coverage agrees within 1 %."""
    m = syn.box_tets(8, jitter=0.2)
    cam = Camera.orbit(m.points, 30, 20, 2.5)
    ref = render(m, None, cam, SIZE, "reference", iso=ISO)
    img = render(m, None, cam, SIZE, "pt", iso=ISO, iso_mode="texture")
    d = np.abs(img - ref) * 255
    assert np.sqrt((d ** 2).mean()) < 6.0 and (d.max(axis=-1) > 4).mean() < 0.08
    assert abs(img[..., 3].mean() - ref[..., 3].mean()) < 0.01 * ref[..., 3].mean()


def test_smooth_isosurfaces_match_reference_and_darken_towards_the_silhouette():
    """Smooth shading (Roettger §8.9): the spherical surface s = 0.3 around the centre of a fine grid, headlight.
    pt equals the reference (the same linear interpolation of vertex intensities, evaluated where the ray crosses
    the surface), the surface facing the camera keeps its flat color and it darkens towards its silhouette."""
    m = syn.box_tets(10)                                                   # s = distance from the centre
    one = build_iso_table([IsoSurface(0.3, (1.0, 0.8, 0.4), 1.0)], n_s=256, s_range=(0.0, 0.9))
    cam = Camera((0.5, 0.5, 3.0), (0.5, 0.5, 0.5), (0, 1, 0), parallel=True, parallel_scale=0.4,
                 clipping_range=(0.1, 10.0))
    ref = render(m, None, cam, SIZE, "reference", iso=one, iso_shading="smooth")
    img = render(m, None, cam, SIZE, "pt", iso=one, iso_shading="smooth")
    flat = render(m, None, cam, SIZE, "pt", iso=one)
    d = (img - ref) * 255.0
    assert float(np.sqrt((d ** 2).mean())) <= 1.0 and float(np.abs(d).max()) <= 4.0
    hit = flat[..., 3] > 0.99
    assert hit.sum() > 200
    assert np.array_equal(img[..., 3], flat[..., 3])                      # shading changes color, not coverage
    ratio = img[hit, 0] / flat[hit, 0]
    assert ratio.max() <= 1.0 + 1e-12 and ratio.max() > 0.95               # facing the light: nearly unshaded
    h, w = SIZE[1], SIZE[0]
    yy, xx = np.nonzero(hit)
    r = np.hypot(xx - (w - 1) / 2, yy - (h - 1) / 2)
    centre, rim = ratio[r < 0.3 * r.max()], ratio[r > 0.85 * r.max()]
    assert rim.mean() < centre.mean() - 0.2                                # oblique normals at the silhouette
    with pytest.raises(ValueError, match="exact"):
        render(m, None, cam, (8, 8), "pt", iso=one, iso_mode="texture", iso_shading="smooth")
