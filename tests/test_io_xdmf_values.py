"""XDMF attribute values held to their fields before VTK's reader runs (``volviz_vtk_readers.xdmf.check_attribute``,
issue #32): the campaign's case of seed 33 swapped a ``Time`` ``Value="1.0"`` with an ``Attribute`` ``Name="T"`` and
VTK read the step at time 0 (a second step at 0); each such swap is refused naming the file, the element, the
attribute and the value, and the undamaged file still reads its values."""
from __future__ import annotations

import meshio
import numpy as np
import pytest
import pyvista as pv

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.model import TimeSeries

GRID = pv.ImageData(dimensions=(2, 2, 2)).cast_to_unstructured_grid().triangulate()
POINTS = np.asarray(GRID.points, dtype=np.float64)
TETS = np.asarray(GRID.cells_dict[pv.CellType.TETRA], dtype=np.int64)


def _series(folder, monkeypatch):
    """meshio's time series of three steps (0, 1, 2) of a point field ``T``: the bench's ``xdmf-tets-3`` seed."""
    monkeypatch.chdir(folder)                    # meshio writes the HDF5 file in the working folder
    path = folder / "mesh.xdmf"
    with meshio.xdmf.TimeSeriesWriter(path) as writer:
        writer.write_points_cells(POINTS, [("tetra", TETS)])
        for t in (0.0, 1.0, 2.0):
            writer.write_data(t, point_data={"T": POINTS[:, 0] + 10 * t})
    return path


def test_the_valid_series_reads_its_times_and_values(tmp_path, monkeypatch):
    series = vio.read(_series(tmp_path, monkeypatch))
    assert isinstance(series, TimeSeries)
    np.testing.assert_array_equal(series.times, [0.0, 1.0, 2.0])
    for i, t in enumerate(series.times):
        frame = series.frame(i)
        index = {tuple(p): k for k, p in enumerate(np.asarray(frame.points))}
        shown = np.asarray(frame.point_data["T"])[[index[tuple(p)] for p in POINTS]]
        np.testing.assert_array_equal(shown, POINTS[:, 0] + 10 * t)


def _swap(text: str, a: str, b: str) -> str:
    """The first attribute value ``"a"`` and the first ``"b"`` after it exchanged (the bench's xml-swap)."""
    i = text.index(f'"{a}"')
    j = text.index(f'"{b}"', i + 1)
    return text[:i] + f'"{b}"' + text[i + len(a) + 2:j] + f'"{a}"' + text[j + len(b) + 2:]


@pytest.mark.parametrize("a, b, problem", [
    ("1.0", "T", r"a Time element's Value 'T' is not a finite number \(a time step\)"),      # the campaign's case
    ("Uniform", "Float", r"a Grid element's GridType 'Float' is not one of XDMF's \(collection, subset, tree, "
                         r"uniform\)"),
    ("XYZ", "8", r"a Geometry element's GeometryType '8' is not one of XDMF's"),
    ("Node", "Scalar", r"an Attribute element's Center 'Scalar' is not one of XDMF's \(cell, edge, face, grid, "
                       r"node, other\)$"),
    ("8", "HDF", r"a DataItem element's Dimensions 'HDF' are not whole numbers >= 0$"),    # Dimensions="8" first
])
def test_swapped_attribute_values_are_refused_naming_the_field(tmp_path, monkeypatch, a, b, problem):
    path = _series(tmp_path, monkeypatch)
    path.write_text(_swap(path.read_text(), a, b))
    with pytest.raises(ReadError, match=f"^{path}: {problem}"):
        vio.read(path)


def test_a_precision_that_is_no_byte_count_and_a_nan_time_are_refused(tmp_path, monkeypatch):
    path = _series(tmp_path, monkeypatch)
    valid = path.read_text()
    path.write_text(valid.replace('Precision="8"', 'Precision="3"', 1))
    with pytest.raises(ReadError, match=f"^{path}: a DataItem element's Precision '3' is not a byte count XDMF "
                                        r"knows \(1, 2, 4 or 8\)$"):
        vio.read(path)
    path.write_text(valid.replace('Value="2.0"', 'Value="nan"'))
    with pytest.raises(ReadError, match=f"^{path}: a Time element's Value 'nan' is not a finite number"):
        vio.read(path)
