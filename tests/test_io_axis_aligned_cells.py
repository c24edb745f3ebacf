"""VTK's axis-aligned cells (a voxel, type 11; a pixel, type 8) read as the general cells they are, corners reordered
(a ``.vtu`` of voxels ended in "internal error: TetMesh has no tetrahedra"): a grid of 5 x 4 x 3 unit voxels becomes
60 hexahedra whose tetrahedra fill exactly its volume, with every tetrahedron positively oriented, and a grid of
pixels becomes quads covering exactly its area."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pyvista as pv

from volviz.io import read
from volviz.model.datasets import VTK_HEXAHEDRON, VTK_QUAD
from volviz.unstructured.tetrahedralize import tetrahedralize


def _saved(grid: pv.ImageData, path: Path) -> Path:
    mesh = grid.cast_to_unstructured_grid()
    mesh.point_data["v"] = np.arange(mesh.n_points, dtype=np.float64)
    mesh.save(path)
    return path


def test_voxels_read_as_hexahedra_filling_their_volume(tmp_path: Path) -> None:
    path = _saved(pv.ImageData(dimensions=(6, 5, 4), spacing=(1.0, 1.0, 1.0)), tmp_path / "voxels.vtu")
    assert set(pv.read(path).celltypes) == {11}
    mesh = read(path, isolate=False)
    assert [(t, c.shape) for t, c in mesh.cells] == [(VTK_HEXAHEDRON, (60, 8))]
    tets = tetrahedralize(mesh, "v")
    p = tets.points[tets.tets]
    signed = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0
    assert np.all(signed > 0) or np.all(signed < 0)        # one orientation: no cell turned inside out
    assert abs(np.abs(signed).sum() - 60.0) < 1e-9


def test_pixels_read_as_quads_covering_their_area(tmp_path: Path) -> None:
    path = _saved(pv.ImageData(dimensions=(5, 4, 1), spacing=(2.0, 1.0, 1.0)), tmp_path / "pixels.vtu")
    assert set(pv.read(path).celltypes) == {8}
    mesh = read(path, isolate=False)
    assert [(t, c.shape) for t, c in mesh.cells] == [(VTK_QUAD, (12, 4))]
    quads = mesh.points[mesh.cells[0][1]]
    edges = np.roll(quads, -1, axis=1) - quads                # around the face: no edge crosses the quad
    assert np.allclose(np.linalg.norm(edges, axis=2), [2.0, 1.0, 2.0, 1.0])
    area = 0.5 * np.abs(np.cross(quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 1])[:, 2])
    assert np.allclose(area, 2.0)
