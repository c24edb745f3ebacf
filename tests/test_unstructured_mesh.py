"""Tetrahedralisation, topology and camera of volviz.unstructured (Roettger §8.2, §11.3.3; Guthe §4.1)."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.datasets import VTK_HEXAHEDRON, VTK_PYRAMID, VTK_TETRA, VTK_WEDGE, TetMesh, UnstructuredMesh
from volviz.model.camera import Camera
from volviz.unstructured.synthetic import box_grid, holed_box
from volviz.unstructured.tetrahedralize import tetrahedralize
from volviz.unstructured.topology import topology, visible_cells


def _volumes(m: TetMesh) -> np.ndarray:
    p = m.points[m.tets]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0


def _interior_faces_shared_twice(m: TetMesh) -> tuple[int, int]:
    faces = np.sort(m.tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    _, counts = np.unique(faces, axis=0, return_counts=True)
    return int((counts == 1).sum()), int((counts > 2).sum())


def test_curvilinear_hexahedra_split_into_five_conforming_tets():
    grid = box_grid(5, jitter=0.25)
    mesh, rep = tetrahedralize(grid, report=True)
    assert rep.n_degenerate == 0 and mesh.n_cells == 5 * 4 ** 3
    vol = _volumes(mesh)
    assert np.all(vol > 0)
    assert vol.sum() == pytest.approx(1.0, abs=1e-12)             # boundary points are not jittered
    boundary, over = _interior_faces_shared_twice(mesh)
    assert over == 0 and boundary == 6 * 16 * 2                    # every interior face exactly twice
    topo = topology(mesh)
    assert int((topo.neighbor < 0).sum()) == boundary == len(topo.boundary)
    assert topology(mesh) is topo                                    # cached


def test_hexahedron_volume_and_both_parities():
    pts = np.array([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0], [0, 0, 5], [2, 0, 5], [2, 3, 5], [0, 3, 5]], float)
    for color0 in (True, False):
        from volviz.unstructured.tetrahedralize import hexahedra_to_tets
        tets = hexahedra_to_tets(np.arange(8)[None], np.array([color0]))
        m = tetrahedralize(TetMesh(pts, tets, np.zeros(8)))
        assert m.n_cells == 5 and _volumes(m).sum() == pytest.approx(30.0)


def test_unstructured_hex_wedge_pyramid_mesh_conforms():
    # a 2x1x1 box: left cube as one hexahedron, right cube as two prisms; plus a pyramid on top of the hexahedron
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1],
                    [2, 0, 0], [2, 1, 0], [2, 0, 1], [2, 1, 1], [0.5, 0.5, 1.7]], float)
    hexes = np.array([[0, 1, 2, 3, 4, 5, 6, 7]])
    wedges = np.array([[1, 8, 9, 5, 10, 11], [1, 9, 2, 5, 11, 6]])
    pyr = np.array([[4, 5, 6, 7, 12]])
    um = UnstructuredMesh(pts, [(VTK_HEXAHEDRON, hexes), (VTK_WEDGE, wedges), (VTK_PYRAMID, pyr)],
                          {"f": pts[:, 0]})
    m, rep = tetrahedralize(um, report=True)
    assert m.n_cells == 5 + 6 + 2 and rep.n_degenerate == 0
    assert _volumes(m).sum() == pytest.approx(2.0 + 0.7 / 3.0)
    boundary, over = _interior_faces_shared_twice(m)
    assert over == 0
    # hexahedron/prism interface (x = 1) and hexahedron/pyramid interface (z = 1) are split consistently
    assert boundary == 2 * (2 + 4 * 2) - 2 + 4                       # box: 10 quads, minus the pyramid base, + 4


def test_degenerate_cells_dropped_and_counted():
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]], float)
    tets = np.array([[0, 1, 2, 3], [0, 1, 2, 4], [0, 2, 1, 3]])     # second is flat, third is inverted
    m, rep = tetrahedralize(UnstructuredMesh(pts, [(VTK_TETRA, tets)], {"s": np.arange(5.0)}), report=True)
    assert rep.n_degenerate == 1 and m.n_cells == 2
    assert np.all(_volumes(m) > 0)


def test_non_bipartite_hex_mesh_split_by_vtk_ordered_triangulation():
    """The notch mesh's quadratic hexahedra (read through their corners) have no conforming 5-split: VTK's ordered
    triangulation splits them, keeping the points, conforming, with the hexahedra's volume."""
    import warnings

    import pyvista as pv

    from conftest import data_file
    from volviz.io import read

    path = data_file("ecosystem/notch_disp.vtu")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        source = read(path)
    assert [(t, c.shape[1]) for t, c in source.cells] == [(VTK_HEXAHEDRON, 8), (VTK_WEDGE, 6)]
    from volviz.model.arrays import select_array

    mesh, rep = tetrahedralize(select_array(source, "Nodal Displacement:0"), report=True)
    assert rep.input_cells == {"ordered triangulation": 2192} and mesh.n_points == source.n_points
    _, over = _interior_faces_shared_twice(mesh)
    assert over == 0
    linear = pv.UnstructuredGrid({int(t): c for t, c in source.cells}, source.points)
    expected = float(linear.compute_cell_sizes(length=False, area=False)["Volume"].sum())
    # the curved plate's hexahedra have non-planar faces, whose volume depends on how they are split: VTK's
    # hexahedron volume and the tetrahedra's differ by 0.22 %
    assert np.abs(_volumes(mesh)).sum() == pytest.approx(expected, rel=3e-3)


def test_pyvista_structured_grid_input():
    grid = box_grid(4).to_pyvista()
    m = tetrahedralize(grid)
    assert m.n_cells == 135 and m.name == "f"


def test_visible_cells_zero_opacity_test():
    m = holed_box(4)
    x = np.array([0.0, 0.2, 0.3, 2.0])
    rho = np.array([0.0, 0.0, 1.0, 1.0])                           # transparent below 0.2
    vis = visible_cells(m, x, rho)
    s = m.scalars[m.tets]
    assert np.array_equal(vis, s.max(axis=1) >= 0.2)


def test_camera_projection_matches_vtk():
    vtk = pytest.importorskip("vtk")
    for parallel in (False, True):
        cam = Camera((3.0, -4.0, 2.5), (0.2, 0.1, -0.3), (0.1, 0.2, 1.0), 35.0, parallel, 1.7, (0.5, 20.0))
        ren = vtk.vtkRenderer()
        win = vtk.vtkRenderWindow()
        win.SetOffScreenRendering(1)
        win.SetSize(160, 120)
        win.AddRenderer(ren)
        cam.apply_to(ren.GetActiveCamera())
        back = Camera.from_pyvista(ren.GetActiveCamera())
        pts = np.random.default_rng(1).uniform(-1, 1, (20, 3))
        ours = cam.project(pts, (160, 120))
        for p, q in zip(pts, ours):
            ren.SetWorldPoint(*p, 1.0)
            ren.WorldToDisplay()
            dx, dy, _ = ren.GetDisplayPoint()
            assert q[0] == pytest.approx(dx - 0.5, abs=1e-6)
            assert q[1] == pytest.approx(120 - dy - 0.5, abs=1e-6)
        assert np.allclose(back.project(pts, (160, 120)), ours)
