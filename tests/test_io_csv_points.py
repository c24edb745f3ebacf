"""Point tables (``volviz.io.csv_points``): the rows of a CSV / TSV as points at its x, y, z columns (any case,
ParaView's ``Points:0..2``, or the columns the options name), the other numeric columns as point arrays, text
columns and rows without coordinates left out with a warning; clear errors for tables without a header or without
coordinates; damaged copies read or refused with a ReadError naming the file; the first open draws the points
coloured by their array."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import volviz.io as vio
from volviz.model import VTK_VERTEX
from volviz.io.registry import spec_of
from volviz.model import UnstructuredMesh

RNG = np.random.default_rng(5)
XYZ = RNG.uniform(-5.0, 5.0, (40, 3))
TEMP = RNG.uniform(250.0, 300.0, 40)


def _table(path, header, rows, sep=","):
    path.write_text(sep.join(header) + "\n" + "\n".join(sep.join(str(v) for v in row) for row in rows) + "\n")
    return path


@pytest.mark.parametrize("sep", [",", ";", "\t", " "])
def test_rows_become_points_with_their_arrays(tmp_path, sep):
    rows = [(*p, t, f"probe{i}") for i, (p, t) in enumerate(zip(XYZ, TEMP))]
    path = _table(tmp_path / ("probes.tsv" if sep == "\t" else "probes.csv"), ["X", "Y", "Z", "temp", "label"], rows,
                  sep)
    assert spec_of(path).name == "csv"
    for isolate in (False, True):
        with pytest.warns(vio.ReadWarning, match="columns of text left out: label"):
            mesh = vio.read(path, isolate=isolate)
        assert isinstance(mesh, UnstructuredMesh) and mesh.n_points == 40
        np.testing.assert_allclose(mesh.points, XYZ, rtol=1e-15)
        np.testing.assert_allclose(mesh.point_data["temp"], TEMP, rtol=1e-15)
        assert list(mesh.point_data) == ["temp"] and mesh.active == "temp"
        (cell_type, conn), = mesh.cells
        assert cell_type == VTK_VERTEX and np.array_equal(conn.ravel(), np.arange(40))


def test_paraview_exports_planar_tables_and_named_columns(tmp_path):
    pv_export = tmp_path / "export.csv"                  # ParaView's "Save Data" of points: quoted names
    pv_export.write_text('"p","Points:0","Points:1","Points:2"\n' + "\n".join(
        f"{t},{x},{y},{z}" for t, (x, y, z) in zip(TEMP, XYZ)) + "\n")
    mesh = vio.read(pv_export)
    np.testing.assert_allclose(mesh.points, XYZ)
    assert list(mesh.point_data) == ["p"]
    plane = _table(tmp_path / "plane.csv", ["x", "y", "v"], [(x, y, t) for (x, y, _), t in zip(XYZ, TEMP)])
    mesh = vio.read(plane)
    np.testing.assert_allclose(mesh.points[:, :2], XYZ[:, :2])
    assert np.all(mesh.points[:, 2] == 0.0)
    geo = _table(tmp_path / "stations.csv", ["lon", "lat", "depth", "salinity"],
                 [(*p, t) for p, t in zip(XYZ, TEMP)])
    with pytest.raises(vio.ReadError, match=r"stations.csv: has no column named x .* its columns are: lon, lat, "
                                            r"depth, salinity; name the coordinate columns with the options x=, y="):
        vio.read(geo)
    mesh = vio.read(geo, x="lon", y="lat", z="depth")
    np.testing.assert_allclose(mesh.points, XYZ)
    with pytest.raises(vio.ReadError, match="has no column 'height' \\(asked for as z\\)"):
        vio.read(geo, x="lon", y="lat", z="height")


def test_rows_without_coordinates_are_left_out(tmp_path):
    lines = ["x,y,z,v", "# a comment line", "1,2,3,10", "4,,6,11", "7,8,9,12", "nan,1,1,13", "1,1,1,"]
    path = tmp_path / "gaps.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(vio.ReadWarning, match="2 of 5 rows have no coordinates"):
        mesh = vio.read(path, isolate=False)
    np.testing.assert_array_equal(mesh.points, [[1, 2, 3], [7, 8, 9], [1, 1, 1]])
    np.testing.assert_array_equal(mesh.point_data["v"][:2], [10, 12])
    assert np.isnan(mesh.point_data["v"][2])               # a missing value is NaN (drawn transparent)


def test_rows_of_another_length_are_left_out_with_a_warning_naming_them(tmp_path):
    """Issue #32: a row cut short by a truncated file made its value column "text" (left out, the warning blaming
    the column), and a row whose decimal point became a comma (5 fields under a 4-column header) was dropped by
    genfromtxt without a word, or read shifted. A separator ending a row is not a field."""
    path = tmp_path / "rows.csv"
    path.write_text("x,y,z,v\n1,2,3,10\n4,5,6,11\n7,8,9,12,\n1,5,2,3,13\n2,2,2,14\n3,3,3\n")
    with pytest.warns(vio.ReadWarning) as caught:
        mesh = vio.read(path, isolate=False)
    assert [str(w.message) for w in caught] == [f"{path}: 2 of 6 rows do not hold the 4 fields its header names "
                                                "(line 5 holds 5, line 7 holds 3) and are left out"]
    np.testing.assert_array_equal(mesh.points, [[1, 2, 3], [4, 5, 6], [7, 8, 9], [2, 2, 2]])
    np.testing.assert_array_equal(mesh.point_data["v"], [10, 11, 12, 14])
    path.write_text("x,y,z,v,label\n1,2,3,10,a\n4,5,6,11,b\n7,8,9,1,2,c\n")  # a text column: no fast parser
    with pytest.warns(vio.ReadWarning, match=r"1 of 3 rows do not hold the 5 fields its header names \(line 4 holds "
                                             r"6\) and are left out"):
        mesh = vio.read(path, isolate=False)
    np.testing.assert_array_equal(mesh.point_data["v"], [10, 11])


@pytest.mark.parametrize("text, problem", [
    ("1,2,3\n4,5,6\n", "has no header row naming its columns"),
    ("a,b,c\n1,2,3\n", "has no column named x"),
    ("x,y,z\n", "has a header row but no rows of values"),
    ("", "holds no rows"),
    ("x,y,z\nleft,2,3\n", "its x column 'x' holds text"),
    ("x,x,z\n1,2,3\n", "empty or repeated column names"),
])
def test_tables_that_are_not_point_tables_are_refused(tmp_path, text, problem):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(vio.ReadError, match=problem) as caught:
        vio.read(path)
    assert str(path) in str(caught.value)
    path.write_bytes(b"x,y,z\n\x00\x01\x02binary")
    with pytest.raises(vio.ReadError, match="not a text table"):
        vio.read(path)


def test_damaged_copies_read_or_are_refused(tmp_path):
    rows = [(*p, t) for p, t in zip(XYZ, TEMP)]
    original = _table(tmp_path / "orig.csv", ["x", "y", "z", "t"], rows).read_bytes()
    path = tmp_path / "damaged.csv"
    rng = np.random.default_rng(11)
    refused = 0
    for k in range(60):
        data = bytearray(original)
        if k % 3 == 0:
            data = data[:int(rng.integers(1, len(data)))]
        else:
            for at in rng.integers(0, len(data), 1 + k % 5):
                data[at] = int(rng.integers(0, 256))
        path.write_bytes(bytes(data))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mesh = vio.read(path, isolate=False)
        except vio.ReadError as exc:
            assert str(path) in str(exc)
            refused += 1
            continue
        assert 0 < mesh.n_points <= 41 and np.isfinite(mesh.points).all()
    assert refused < 60


def test_a_point_table_opens_drawn_as_points(tmp_path):
    from volviz.render.export import render_session
    from volviz.scene.opening import data_session

    cloud = RNG.normal(0.0, 1.0, (400, 3))
    path = _table(tmp_path / "cloud.csv", ["x", "y", "z", "r"], [(*p, np.linalg.norm(p)) for p in cloud])
    image = render_session(data_session(path), None, (200, 150)).astype(int)
    drawn = np.abs(image - image[0, 0]).sum(axis=2) > 60
    assert 0.03 < drawn[:, :150].mean() < 0.6                  # points, not an empty or filled view
    assert len(np.unique(image[:, :150][drawn[:, :150]] // 32, axis=0)) > 5     # coloured by r
