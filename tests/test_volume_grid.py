"""The grid a dataset is drawn from (``volviz.render.vtk_scene.volume_grid``): vectors are drawn by their magnitude,
beside them (issue #28, found driving the app as a new user: Fluent's room case, whose first array is the
2-component cell array SV_BF_V, failed with "Array 'magnitude' has length (4338) but a length of (4565) was
expected": the magnitude of cell vectors was put on the points)."""
from __future__ import annotations

import numpy as np

from conftest import data_file
from volviz.io import read
from volviz.render.vtk_scene import volume_grid


def test_cell_vectors_are_drawn_by_their_magnitude_on_the_cells() -> None:
    room = read(data_file("ecosystem/fluent-room/room.cas.h5"))
    vectors = room.to_pyvista().cell_data["SV_BF_V"]
    grid = volume_grid(room)
    assert grid.active_scalars_info.association.name == "CELL" and grid.active_scalars_info.name == "magnitude"
    assert vectors.shape == (4338, 2) and grid.n_cells == 4338 and grid.n_points == 4565
    np.testing.assert_array_equal(grid.cell_data["magnitude"], np.linalg.norm(vectors, axis=1))


def test_point_vectors_are_drawn_by_their_magnitude_on_the_points() -> None:
    import pyvista as pv

    grid = pv.ImageData(dimensions=(3, 4, 5))
    vectors = np.arange(grid.n_points * 3, dtype=float).reshape(-1, 3)
    grid.point_data["v"] = vectors
    grid.set_active_scalars("v")
    shown = volume_grid(grid)
    assert shown.active_scalars_info.association.name == "POINT" and shown.active_scalars_info.name == "magnitude"
    np.testing.assert_array_equal(shown.point_data["magnitude"], np.linalg.norm(vectors, axis=1))
