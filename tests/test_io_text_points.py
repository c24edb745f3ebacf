"""Point clouds as plain text (``.xyz``, ``.pts``, ``.txt``, or any name, known by content: ``is_point_text``): a
header-less table of 3 or more numeric columns opens as points with the extra columns as arrays, through the point
table reader (``volviz.io.csv_points``). Compared with VTK's vtkSimplePointsReader and vtkDelimitedTextReader."""
from __future__ import annotations

import numpy as np
import pytest
from vtk.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from volviz.io.csv_points import is_point_text
from volviz.io.errors import ReadError
from volviz.io.registry import format_of
from volviz.model import UnstructuredMesh
from volviz.model.arrays import default_array, vertex_colors

RNG = np.random.default_rng(7)
POINTS = RNG.normal(size=(300, 3)) * [10.0, 20.0, 5.0]


def _vtk_simple_points(path) -> np.ndarray:
    import vtk

    reader = vtk.vtkSimplePointsReader()
    reader.SetFileName(str(path))
    reader.Update()
    return vtk_to_numpy(reader.GetOutput().GetPoints().GetData())


def _vtk_table_column(path, delimiter: str, column: int) -> np.ndarray:
    import vtk

    reader = vtk.vtkDelimitedTextReader()
    reader.SetFileName(str(path))
    reader.SetFieldDelimiterCharacters(delimiter)
    reader.SetHaveHeaders(False)
    reader.DetectNumericColumnsOn()
    reader.Update()
    return vtk_to_numpy(reader.GetOutput().GetColumn(column))


def test_an_xyz_file_of_three_columns_is_points_as_vtk_reads_them(tmp_path):
    path = tmp_path / "cloud.xyz"
    np.savetxt(path, POINTS, fmt="%.6f", header="scanner export", comments="# ")
    assert format_of(path, {}) == "points-text"
    mesh = vio.read(path)
    assert isinstance(mesh, UnstructuredMesh) and mesh.n_points == 300 and mesh.point_data == {}
    np.testing.assert_allclose(mesh.points, np.round(POINTS, 6), atol=1e-9)
    assert default_array(mesh) is None
    bare = tmp_path / "bare.xyz"  # vtkSimplePointsReader knows no comment lines
    np.savetxt(bare, POINTS, fmt="%.6f")
    np.testing.assert_array_equal(vio.read(bare).points, mesh.points)
    np.testing.assert_allclose(mesh.points, _vtk_simple_points(bare), rtol=1e-6)


def test_extra_columns_are_arrays_in_any_separator_and_any_name(tmp_path):
    values = np.column_stack([POINTS, POINTS[:, 0] * 2 + 1, POINTS[:, 2] ** 2])
    for name, sep in (("survey.txt", ","), ("survey.dat", "\t"), ("survey", " ")):
        path = tmp_path / name
        np.savetxt(path, values, fmt="%.5f", delimiter=sep)
        mesh = vio.read(path)
        assert sorted(mesh.point_data) == ["column 4", "column 5"], name
        np.testing.assert_allclose(mesh.point_data["column 4"], np.round(values[:, 3], 5), atol=1e-9)
        np.testing.assert_allclose(mesh.point_data["column 5"], _vtk_table_column(path, sep, 4), rtol=1e-12)
        assert default_array(mesh) == "column 4"


def test_a_leica_pts_file_has_its_count_skipped_intensity_and_colours(tmp_path):
    intensity = RNG.integers(-2048, 2047, size=300)
    rgb = RNG.integers(0, 256, size=(300, 3))
    path = tmp_path / "scan.pts"
    with open(path, "w") as f:
        f.write("300\n")
        for p, i, c in zip(POINTS, intensity, rgb):
            f.write(f"{p[0]:.4f} {p[1]:.4f} {p[2]:.4f} {i} {c[0]} {c[1]} {c[2]}\n")
    mesh = vio.read(path)
    assert mesh.n_points == 300 and sorted(mesh.point_data) == ["blue", "green", "intensity", "red"]
    np.testing.assert_array_equal(mesh.point_data["intensity"], intensity)
    np.testing.assert_array_equal(vertex_colors(mesh), rgb.astype(np.uint8))
    assert default_array(mesh) == "intensity"


def test_a_header_row_naming_x_y_z_still_names_the_columns(tmp_path):
    path = tmp_path / "probe.txt"
    np.savetxt(path, np.column_stack([POINTS, POINTS[:, 1]]), fmt="%.4f", header="X Y Z T", comments="")
    mesh = vio.read(path)
    assert list(mesh.point_data) == ["T"]
    np.testing.assert_allclose(mesh.point_data["T"], np.round(POINTS[:, 1], 4), atol=1e-9)


def test_text_that_is_no_point_table_is_not_taken(tmp_path):
    assert not is_point_text(b"1 2\n3 4\n5 6\n")                         # two columns
    assert not is_point_text(b"1 2 3\n4 5\n6 7 8\n")                    # ragged rows
    assert not is_point_text(b"10 5 0 0 0\n1 0.0 0.0 0.0\n2 1.0 0.0 0.0\n")  # AVS UCD counts, then nodes
    assert not is_point_text(b"v 1 2 3\nv 4 5 6\n")                      # Wavefront OBJ
    assert not is_point_text(b"Dear reader, 1 2 3\n")
    assert not is_point_text(b"1 2 3\x00\n")
    (tmp_path / "notes.txt").write_text("Measurements of the 3 samples\nwere taken on 2 days\n")
    with pytest.raises(ReadError, match=r"notes.txt: .*content: text"):
        vio.read(tmp_path / "notes.txt")
    (tmp_path / "pairs.txt").write_text("1 2\n3 4\n")
    with pytest.raises(ReadError, match=r"pairs.txt: "):
        vio.read(tmp_path / "pairs.txt")
