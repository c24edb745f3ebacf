"""Tecplot ASCII through the VTK-readers plugin: a zone with cell-centred variables (VARLOCATION) read as VTK's
vtkTecplotReader reads it (``ecosystem/cellcentered.tec``), and files cut short refused with one line naming the zone
(``volviz_vtk_readers.tecplotcheck``), where VTK's reader loops for a minute or returns an empty mesh."""
from __future__ import annotations

import numpy as np
import pytest
from vtk.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from conftest import data_file
from volviz.cli import main
from volviz.io.errors import ReadError
from volviz.model import UnstructuredMesh


def _vtk_zones(path):
    import vtk

    reader = vtk.vtkTecplotReader()
    reader.SetFileName(str(path))
    reader.Update()
    out = reader.GetOutput()
    return [out.GetBlock(i) for i in range(out.GetNumberOfBlocks())]


def test_cell_centred_variables_are_cell_arrays_as_vtk_reads_them():
    path = data_file("ecosystem/cellcentered.tec")
    zones = _vtk_zones(path)
    mesh = vio.read(path)
    assert isinstance(mesh, UnstructuredMesh) and (mesh.n_points, mesh.n_cells) == (8, 2)
    assert sorted(mesh.cell_data) == ["P", "Q", "T"] and sorted(mesh.point_data) == ["V"]
    for name in ("P", "Q", "T"):
        expected = np.concatenate([vtk_to_numpy(z.GetCellData().GetArray(name)) for z in zones])
        np.testing.assert_array_equal(mesh.cell_data[name], expected)
        assert all(z.GetPointData().GetArray(name) is None for z in zones)
    np.testing.assert_array_equal(mesh.cell_data["Q"], np.float32([1.2256, -1.2256]))
    expected_v = np.concatenate([vtk_to_numpy(z.GetPointData().GetArray("V")) for z in zones])
    np.testing.assert_array_equal(mesh.point_data["V"], expected_v)
    np.testing.assert_array_equal(mesh.point_data["V"], np.float32([0.2, 0.25, 0.3, 0.05] * 2))


def _point_zone(rows: int | None = None) -> str:
    lines = ['TITLE="t"', 'VARIABLES="X","Y","Z","P"', 'ZONE T="block", I=4, J=3, K=2, DATAPACKING=POINT']
    lines += [f"{i} {j} {k} {i * j + k}" for k in range(2) for j in range(3) for i in range(4)]
    return "\n".join(lines[:rows]) + "\n"


def test_a_complete_ordered_zone_reads_and_zones_cut_short_are_refused(tmp_path):
    whole = tmp_path / "whole.tec"
    whole.write_text(_point_zone())
    grid = vio.read(whole)  # one ordered zone keeps its structure
    assert grid.dimensions == (4, 3, 2)
    i, j, k = np.meshgrid(np.arange(4), np.arange(3), np.arange(2), indexing="ij")
    np.testing.assert_array_equal(grid.point_data["P"], i * j + k)
    text = data_file("ecosystem/cellcentered.tec").read_text()
    cases = {
        "rows.tec": (_point_zone(15), r"zone 1 \(block\), at line 3, holds 48 values where its header needs 96 "
                                      r"\(4 variables on 4x3x2 points\): the file is truncated"),
        "header.tec": (_point_zone(3), r"zone 1 \(block\), at line 3, holds no values: the file is truncated"),
        "fe.tec": (text[:200], r"zone 1 \(ZONE1\), at line 3, holds 17 values where its header needs 23 \(7 variables "
                               r"on 4 nodes, 1 quadrilateral elements and their connectivity\)"),
        "second.tec": (text[:300], r"zone 2 \(ZONE2\), at line 10, holds no values"),
        "midline.tec": (text[:100], r"zone 1 \(ZONE1\), at line 3, holds no values"),
    }
    for name, (content, message) in cases.items():
        (tmp_path / name).write_text(content)
        with pytest.raises(ReadError, match=rf"^{tmp_path / name}: {message}"):
            vio.read(tmp_path / name)


def test_the_cli_says_one_line_and_exits_non_zero(tmp_path, capsys):
    cut = tmp_path / "cut.tec"
    cut.write_text(_point_zone(12))
    for command in (["info", str(cut)], ["render", str(cut), "-o", str(tmp_path / "x.png")]):
        assert main(command) != 0
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and f"{cut}: zone 1 (block)" in err and "truncated" in err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("old, new, problem", [
    # the campaign's field: the '-6' of VARLOCATION's [4,5-6] set to -2147483648 (1.37 s, then VTK's memory limit)
    (b"5-6", b"5-2147483648", "zone 1 (ZONE1), at line 3: VARLOCATION names variables 5-2147483648 but the file has "
                              "7 variables (1 to 7)"),
    (b"N=4", b"N=-2147483648", "zone 1 (ZONE1), at line 3: N=-2147483648; a count cannot be negative"),
    (b"I=2", b"I=-1", "zone 2 (ZONE2), at line 10: I=-1; a count cannot be negative"),
], ids=["varlocation", "nodes", "ordered"])
def test_nonsensical_zone_counts_are_refused_before_vtk(tmp_path, old, new, problem):
    path = tmp_path / "cellcentered.tec"
    path.write_bytes(data_file("ecosystem/cellcentered.tec").read_bytes().replace(old, new, 1))
    with pytest.raises(ReadError) as info:
        vio.read(path)
    assert str(info.value) == f"{path}: {problem}"
