"""A cell array shown at the points (``volviz.model.arrays.select_array``) is the mean of the cells around each
point, computed with NumPy on the thread that asks: held to VTK's cell-to-point filter, the reference it replaced
(making VTK objects on the app's worker threads can deadlock a render, ``volviz.jobs``), on the real files with cell
arrays: unstructured meshes of hexahedra, polyhedra and quadrilaterals, and flat curvilinear grids with NaN."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import data_file
from volviz.model import CurvilinearGrid, TimeSeries

FILES = ["ecosystem/openfoam-cavity/case.foam", "ecosystem/sampleCurveGrid4.nc", "ecosystem/tos_O1_2001-2002.nc",
         "ecosystem/sqnz_s.adf.cgns", "ecosystem/coarseGrid.e", "ecosystem/fluent-room/room.cas.h5",
         "ecosystem/cellcentered.tec"]


def _vtk_cell_to_point(dataset, scalar: np.ndarray) -> np.ndarray:
    """VTK's vtkCellDataToPointData on the dataset's grid (what ``_cell_to_point`` did before)."""
    grid = CurvilinearGrid(dataset.points).to_pyvista() if isinstance(dataset, CurvilinearGrid) \
        else dataset.to_pyvista()
    grid.clear_data()
    curvilinear = isinstance(dataset, CurvilinearGrid)
    grid.cell_data["c"] = np.asarray(scalar.reshape(-1, order="F") if curvilinear else scalar, np.float64)
    values = np.asarray(grid.cell_data_to_point_data().point_data["c"])
    return values.reshape(dataset.dimensions, order="F") if curvilinear else values


@pytest.mark.parametrize("name", FILES)
def test_cell_arrays_at_the_points_match_vtks_filter(name: str) -> None:
    from volviz.io import read
    from volviz.model.arrays import list_arrays, select_array

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dataset = read(data_file(name))
    if isinstance(dataset, TimeSeries):
        dataset = dataset.frame(1)       # the cavity moves from its second step on
    cells = [info for info in list_arrays(dataset) if info.association == "cell"]
    assert cells
    for info in cells:
        spec = info.choices[0]
        shown = select_array(dataset, spec)
        values = np.asarray(dataset.cell_data[info.name], np.float64)
        if info.components > 1:
            values = np.linalg.norm(values.reshape(values.shape[:3 if isinstance(dataset, CurvilinearGrid) else 1]
                                                   + (-1,)), axis=-1)
        expected = _vtk_cell_to_point(dataset, values)
        got = shown.point_data[spec]
        assert got.shape == expected.shape
        assert np.array_equal(np.isnan(got), np.isnan(expected)), (name, spec)
        assert np.allclose(got, expected, rtol=1e-12, atol=1e-12, equal_nan=True), (name, spec)
