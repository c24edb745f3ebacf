"""Method "pt" against the exact "reference" on the hard cases of Roettger §15.2 / Guthe §7.2, and the reference
against closed forms. Errors in 8-bit units of premultiplied RGBA; bounds: RMSE <= 1, max <= 4."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import data_file
from volviz.model.datasets import TetMesh
from volviz.optics import TransferFunction
from volviz.optics.metrics import max_abs, rmse
from volviz.unstructured import synthetic as syn
from volviz.model.camera import Camera
from volviz.unstructured.render import render

TF = TransferFunction([0.0, 0.3, 0.6, 0.9], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], [0.0, 3.0, 6.0, 1.0])
SIZE = (40, 32)


def _err(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    d = (a - b) * 255.0
    return float(np.sqrt((d ** 2).mean())), float(np.abs(d).max())


def _check(mesh, cam, tf=TF, size=SIZE, rmse=1.0, mx=4.0, min_alpha=0.05):
    ref = render(mesh, tf, cam, size, "reference")
    img = render(mesh, tf, cam, size, "pt")
    assert img.shape == (size[1], size[0], 4) and np.all(np.isfinite(img)) and np.all(np.isfinite(ref))
    assert ref[..., 3].max() > min_alpha                            # the view shows something
    e = _err(img, ref)
    assert e[0] <= rmse and e[1] <= mx, e
    return img, ref


def test_reference_single_tet_matches_closed_form():
    # constant scalar, orthographic view along z through a right tetrahedron: l = 1 - x - y at pixel centre (x, y)
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    tf = TransferFunction([0.0, 1.0], [[0.2, 0.5, 1.0]] * 2, [2.0, 2.0])
    m = TetMesh(pts, np.array([[0, 1, 2, 3]]), np.full(4, 0.5))
    cam = Camera((0.5, 0.5, 5.0), (0.5, 0.5, 0.0), (0, 1, 0), parallel=True, parallel_scale=0.5,
                 clipping_range=(0.1, 10))
    img = render(m, tf, cam, (16, 16), "reference")
    col, row = np.meshgrid(np.arange(16), np.arange(16))
    x, y = (col + 0.5) / 16, 1.0 - (row + 0.5) / 16
    l = np.clip(1.0 - x - y, 0, None)
    alpha = 1.0 - np.exp(-2.0 * l)
    assert np.allclose(img[..., 3], alpha, atol=1e-12)
    assert np.allclose(img[..., 2], alpha * 1.0, atol=1e-12) and np.allclose(img[..., 0], 0.2 * alpha, atol=1e-12)


def test_one_tet_perspective_and_parallel():
    pts = np.array([[0, 0, 0], [1, 0.1, 0], [0.2, 1, 0.1], [0.3, 0.2, 0.9]], float)
    m = TetMesh(pts, np.array([[0, 1, 2, 3]]), np.array([0.1, 0.5, 0.8, 0.35]))
    for cam in (Camera.orbit(pts, 25, 30, 2.0), Camera.orbit(pts, 25, 30, 2.0, parallel=True)):
        _check(m, cam, tf=TF.scaled_extinction(5.0))


def test_slivers_and_near_degenerate():
    m = syn.box_tets(5, jitter=0.45, seed=3)                     # heavy jitter: flat, needle-like cells
    sliver = TetMesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.3, 0.3, 1e-3]], float), np.array([[0, 1, 2, 3]]),
                     np.array([0.3, 0.5, 0.6, 0.45]))
    _check(m, Camera.orbit(m.points, 35, 25, 2.5))
    tf = TF.scaled_extinction(20.0)                               # optical depth ~0.15 across the sliver
    _check(sliver, Camera.orbit(sliver.points, 10, 60, 2.5), tf=tf)


def test_view_exactly_along_faces_and_edges():
    m = syn.box_tets(4)                                            # faces at x, y, z = 0, 1/3, 2/3, 1
    along_z = Camera((0.5, 0.5, 4.0), (0.5, 0.5, 0.0), (0, 1, 0), parallel=True, parallel_scale=0.6,
                     clipping_range=(0.1, 10))
    diag = Camera((0.5 + 3, 0.5 + 3, 0.5), (0.5, 0.5, 0.5), (0, 0, 1), 30.0, clipping_range=(0.1, 10))
    for cam in (along_z, diag):
        _check(m, cam, size=(33, 33))


def test_camera_inside_mesh_near_plane_clipping():
    m = syn.box_tets(5, jitter=0.2)
    cam = Camera((0.45, 0.55, 0.5), (1.0, 0.8, 0.6), (0, 0, 1), 70.0, clipping_range=(0.05, 10.0))
    img, ref = _check(m, cam)
    assert ref[..., 3].min() > 0.0                                 # every pixel looks through the medium


def test_near_plane_crossing_cells_get_the_box_of_their_visible_part():
    """A cell crossing the near plane is drawn over the pixel box of its part in front of the plane (front vertices
    and the edges' crossings of the plane), not the whole screen; a cell wholly behind the plane has no box. Before,
    every crossing cell got the whole screen: a near plane through a large mesh took minutes per frame."""
    cam = Camera((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0, 1, 0), 60.0, clipping_range=(1.0, 100.0))
    pts = np.array([[0.01, 0.01, 0.9], [0.05, 0.0, 1.2], [0.0, 0.05, 1.2], [0.03, 0.03, 1.5]])
    crossing = TetMesh(pts, np.array([[0, 1, 2, 3]]), np.array([0.2, 0.5, 0.7, 0.4]))
    size = (160, 120)
    img, st = render(crossing, TF, cam, size, "pt", return_stats=True)
    ref = render(crossing, TF, cam, size, "reference")
    assert ref[..., 3].max() > 0.01                                # the part in front of the plane is seen
    assert rmse(img, ref) <= 0.5 and max_abs(img, ref) <= 2.0
    assert 0 < st.extra["box_pixels"] < 0.05 * size[0] * size[1]
    behind = TetMesh(pts - np.array([0.0, 0.0, 0.5]), crossing.tets, crossing.scalars)
    img, st = render(behind, TF, cam, size, "pt", return_stats=True)
    assert st.extra["box_pixels"] == 0 and not img.any()


def test_flat_cell_renders_nothing():
    """A tetrahedron whose four vertices lie in one plane (zero volume) is no error and draws nothing."""
    flat = TetMesh(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 0.0]]),
                   np.array([[0, 1, 2, 3]]), np.array([0.2, 0.5, 0.7, 0.4]))
    cam = Camera.orbit(flat.points, 30, 20, 2.5)
    for method in ("pt", "reference"):
        img = render(flat, TF, cam, (32, 24), method)
        assert np.isfinite(img).all() and np.abs(img).max() <= 1e-12


@pytest.mark.parametrize("make", [syn.cavity_box, syn.holed_box], ids=["cavity", "hole"])
def test_nonconvex_no_missing_or_doubled_cells(make):
    m = make(7)
    for cam in (Camera.orbit(m.points, 30, 20, 2.5), Camera.orbit(m.points, 0, 89, 2.5, up=(0, 1, 0))):
        _check(m, cam)
        # centroid sort draws the same cells: no cell missing or doubled, only the order may differ
        img = render(m, TF, cam, SIZE, "pt", sort="centroid")
        ref = render(m, TF, cam, SIZE, "reference")
        assert abs(img[..., 3].sum() - ref[..., 3].sum()) / ref[..., 3].sum() < 0.02


def test_coordinates_offset_by_1e6():
    m = syn.box_tets(4, jitter=0.3)
    cam0 = Camera.orbit(m.points, 30, 20, 2.5)
    off = np.array([1e6, -2e6, 1e6])
    m2 = TetMesh(m.points + off, m.tets, m.scalars)
    cam2 = Camera(cam0.position + off, cam0.focal_point + off, cam0.view_up, cam0.view_angle,
                  clipping_range=cam0.clipping_range)
    img0, _ = _check(m, cam0)
    img2, _ = _check(m2, cam2)
    assert _err(img0, img2)[1] < 1e-3


def test_nan_scalars_are_transparent():
    m = syn.box_tets(4)
    s = m.scalars.copy()
    s[::7] = np.nan
    mn = TetMesh(m.points, m.tets, s)
    cam = Camera.orbit(m.points, 30, 20, 2.5)
    img, ref = _check(mn, cam)
    full = render(m, TF, cam, SIZE, "reference")
    assert ref[..., 3].sum() < full[..., 3].sum()                 # NaN cells removed, not NaN output


def test_bluntfin_small():
    from volviz.io.plot3d import read_plot3d
    from volviz.unstructured.tetrahedralize import tetrahedralize

    xyz = data_file("bluntfin/bluntfinxyz.bin")
    q = data_file("bluntfin/bluntfinq.bin")
    mesh, rep = tetrahedralize(read_plot3d(xyz, q), "Density", report=True)
    assert rep.n_tets + rep.n_degenerate == 187_395
    tf = TransferFunction([0.19, 1.0, 2.0, 3.0, 5.0],
                          [[0.2, 0.3, 1.0], [0.2, 0.9, 0.9], [1.0, 0.9, 0.2], [1.0, 0.3, 0.1], [1, 1, 1]],
                          [0.0, 0.05, 0.3, 0.8, 0.0])
    cam = Camera.orbit(mesh.points, 40, 25, 1.6, up=(0, 0, 1))
    _check(mesh, cam, tf=tf, size=(48, 48))


def test_shirley_tuchman_classes_and_classic_pt():
    """Classic PT (3/4 triangles, thick-vertex values interpolated linearly) equals the per-pixel path for parallel
    projection (Roettger §8.4) and is only approximate under perspective."""
    m = syn.box_tets(5, jitter=0.3)
    par = Camera.orbit(m.points, 10, 5, 3.0, parallel=True)
    img, st = render(m, TF, par, SIZE, "pt-st", return_stats=True)
    cls = st.extra["classes"]
    assert cls[0] == 0 and cls[1] + cls[2] == m.n_cells and cls[1] > 0 and cls[2] > 0
    assert st.extra["triangles"] == 3 * cls[1] + 4 * cls[2]
    exact = render(m, TF, par, SIZE, "pt", lookup="3d")                 # the same (3D) table as "pt-st"
    assert _err(img, exact)[1] < 1e-6
    # degenerate projections: a regular grid seen exactly along z has edge-on faces and vertices on edges
    along = Camera((0.5, 0.5, 4.0), (0.5, 0.5, 0.0), (0, 1, 0), parallel=True, parallel_scale=0.6,
                   clipping_range=(0.1, 10))
    grid = syn.box_tets(4)
    img, st = render(grid, TF, along, (33, 33), "pt-st", return_stats=True)
    assert st.extra["classes"][0] > 0                            # vertices on edges / on one point
    assert _err(img, render(grid, TF, along, (33, 33), "reference"))[1] <= 4.0


@pytest.mark.parametrize("lookup,degree,scale", [("separable", 2, 1.0), ("separable", 4, 4.0), ("3d", None, 4.0),
                                                 ("auto", None, 8.0)])
def test_every_lookup_matches_reference(lookup, degree, scale):
    """Separable (Roettger §9.1: exact opacity, color polynomial in l) and 3D tables, and the automatic choice by
    optical depth per cell (2 ... 20 here)."""
    m = syn.box_tets(5, jitter=0.3)
    tf = TF.scaled_extinction(scale)
    cam = Camera.orbit(m.points, 25, 30, 2.0)
    ref = render(m, tf, cam, SIZE, "reference")
    img = render(m, tf, cam, SIZE, "pt", lookup=lookup, degree=degree)
    e = _err(img, ref)
    assert e[0] <= 0.5 and e[1] <= 2.0, e


def test_million_tetrahedra_small_image():
    """A conforming grid of 1,026,895 tetrahedra (59^3 hexahedra x 5) at 24 x 20 pixels: the MPVO order, the
    projection and the raster scale to 10^6 cells and still match the reference."""
    m = syn.box_tets(60)
    assert m.n_cells == 5 * 59 ** 3 > 10 ** 6
    cam = Camera.orbit(m.points, 30, 20, 2.5)
    img, st = render(m, TF, cam, (24, 20), "pt", return_stats=True)
    ref = render(m, TF, cam, (24, 20), "reference")
    assert st.n_visible > 10 ** 5 and st.cycles == 0 and ref[..., 3].max() > 0.5
    e = _err(img, ref)
    assert e[0] <= 1.0 and e[1] <= 4.0, e


def test_widened_table_is_kept_until_the_table_is_rebuilt():
    from volviz.optics import build_table3d
    from volviz.unstructured.raster import lut_args

    table = build_table3d(TF, n_s=32, n_l=8)
    first = lut_args(table)[0]
    assert lut_args(table)[0] is first                          # converted once, not every frame
    table.rebuild(TF.scaled_extinction(0.5))                    # same array, changed in place for a new TF
    again = lut_args(table)[0]
    assert again is not first and np.array_equal(again, table.rgba.astype(np.float64).ravel())
