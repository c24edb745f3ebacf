"""A file of points without cells (a PLY of vertices only, a VTK PolyData with points and no vertex cells, as
scanners and exporters write them) opens as a point cloud: one vertex cell per point, drawn as points. It used to
end in "internal error: ValueError: need at least one array to concatenate" in ``volviz render`` (issue #30: never
a blank first image)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pyvista as pv
import pytest
from PIL import Image

from volviz.io import read
from volviz.model import VTK_VERTEX, UnstructuredMesh

N = 400


def _points() -> np.ndarray:
    return np.random.default_rng(3).random((N, 3))


def _ply(folder: Path) -> Path:
    path = folder / "cloud.ply"
    meshio.write_points_cells(path, _points(), [], point_data={"intensity": _points()[:, 0]})
    return path


def _vtp(folder: Path) -> Path:
    path = folder / "cloud.vtp"
    cloud = pv.PolyData()
    cloud.points = _points()
    cloud.point_data["intensity"] = _points()[:, 0]
    assert cloud.n_cells == 0
    cloud.save(path)
    return path


@pytest.mark.parametrize("make", [_ply, _vtp], ids=["ply", "vtp"])
def test_points_without_cells_read_as_one_vertex_per_point(tmp_path: Path, make) -> None:
    mesh = read(make(tmp_path))
    assert isinstance(mesh, UnstructuredMesh)
    assert mesh.n_points == N and mesh.n_cells == N
    ((cell_type, conn),) = mesh.cells
    assert cell_type == VTK_VERTEX and np.array_equal(conn[:, 0], np.arange(N))   # each point once
    np.testing.assert_allclose(mesh.points, _points(), rtol=1e-6)
    np.testing.assert_allclose(mesh.point_data["intensity"], _points()[:, 0], rtol=1e-6)


def test_a_mesh_with_cells_keeps_them() -> None:
    tri = np.array([[0, 1, 2]])
    mesh = UnstructuredMesh(np.eye(3), [(5, tri)])
    assert mesh.cells[0][0] == 5 and np.array_equal(mesh.cells[0][1], tri)


@pytest.mark.parametrize("make", [_ply, _vtp], ids=["ply", "vtp"])
def test_volviz_render_draws_the_points(tmp_path: Path, make) -> None:
    out = tmp_path / "cloud.png"
    done = subprocess.run([sys.executable, "-m", "volviz.cli", "render", str(make(tmp_path)), "-o", str(out),
                           "--size", "320x240"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rgb = np.asarray(Image.open(out).convert("RGB"), dtype=int)
    background = rgb[2, 2]
    # points coloured by intensity (a cool-warm map): many pixels far from the background and from grey
    coloured = (np.abs(rgb - background).sum(axis=2) > 60) & (np.ptp(rgb, axis=2) > 40)
    assert coloured.sum() > 200
