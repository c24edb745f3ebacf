"""Triangles crossing the near plane are cut there in the CPU isosurface modes (as OpenGL clips), not dropped."""
from __future__ import annotations

import numpy as np

from volviz.iso.composite import fragments, render
from volviz.iso.extract import IsoMesh, IsoStyle
from volviz.iso.raster import clip_near_plane, rasterize
from volviz.model.camera import Camera


def _area(pts: np.ndarray, tris: np.ndarray) -> float:
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2)


def test_clip_near_plane_cuts_exactly():
    pts = np.array([[0.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0],     # one vertex in front
                    [0.0, 1.0, 1.0], [1.0, -1.0, 1.0], [-1.0, -1.0, 1.0],    # two vertices in front
                    [0.0, 2.0, 2.0], [1.0, 3.0, 2.0], [-1.0, 3.0, 2.0],      # wholly beyond
                    [0.0, -2.0, 3.0], [1.0, -3.0, 3.0], [-1.0, -3.0, 3.0]])  # wholly in front
    tris = np.arange(12).reshape(4, 3)
    values = pts[:, 1:2] * 2.0 + 1.0  # a linear attribute
    out_pts, out_tris, out_val, parent = clip_near_plane(pts, tris, values, np.zeros(3), np.array([0.0, 1.0, 0.0]),
                                                         0.0)
    assert parent.tolist() == [2, 1, 0, 0]          # kept triangles first, then the cut ones by case
    assert _area(out_pts, out_tris[parent == 2]) == 1.0
    assert abs(_area(out_pts, out_tris[parent == 0]) - 1.5) < 1e-12   # trapezoid beyond y = 0
    assert abs(_area(out_pts, out_tris[parent == 1]) - 0.5) < 1e-12   # the tip beyond y = 0
    assert out_pts[out_tris].reshape(-1, 3)[:, 1].min() >= 0.0
    assert np.allclose(out_val[:, 0], out_pts[:, 1] * 2.0 + 1.0, atol=1e-12)   # linear attribute exact


def test_floor_crossing_the_near_plane_is_drawn_up_to_the_horizon():
    # a 20 x 20 floor at z = 0 under a camera at height 2 looking horizontally: both triangles cross the near plane
    floor = np.array([[-10.0, -10.0, 0.0], [10.0, -10.0, 0.0], [10.0, 10.0, 0.0], [-10.0, 10.0, 0.0]])
    mesh = IsoMesh(floor, np.array([[0, 1, 2], [0, 2, 3]]), np.tile([0.0, 0.0, 1.0], (4, 1)),
                   IsoStyle(0.0, (0.8, 0.8, 0.8), 0.5))
    cam = Camera((0.0, 0.0, 2.0), (0.0, 10.0, 2.0), (0.0, 0.0, 1.0), 60.0, clipping_range=(0.1, 100.0))
    size = (64, 48)
    old = rasterize(cam.project(floor, size), np.ones(4), mesh.triangles, size)
    assert len(old[0]) == 0  # the rasteriser alone drops them (the old behaviour)

    fr = fragments([mesh], cam, size, shading="flat")
    covered = (np.diff(fr.ptr) > 0).reshape(size[1], size[0])
    # analytic: the pixel ray hits the floor inside the square
    rays = cam.rays(size)
    cols, rows = np.meshgrid(np.arange(size[0]), np.arange(size[1]))
    d = rays.d0 + cols[..., None] * rays.dx + rows[..., None] * rays.dy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -rays.o0[2] / d[..., 2]
    hit = rays.o0 + t[..., None] * d
    inside = (d[..., 2] < 0) & (np.abs(hit[..., 0]) <= 10) & (np.abs(hit[..., 1]) <= 10)
    assert inside.mean() > 0.3
    assert (covered != inside).mean() < 0.02          # only pixels on the square's far edge may differ
    assert covered[-1].all() and not covered[0].any()  # under the camera: drawn; sky: empty
    # depth along the view = hit distance along the forward axis (perspective-correct), exactly
    depth = np.array([fr.depth[fr.ptr[p]] for p in np.flatnonzero(covered.ravel())])
    expected = (hit.reshape(-1, 3)[covered.ravel()] - cam.position) @ cam.frame()[2]
    assert np.allclose(depth, expected, rtol=1e-9)
    img, stats = render([mesh], cam, size, "exact", shading="flat", lighting=False)
    assert stats.triangles == 2 and np.allclose(img[-1, :, 3], 0.5)
