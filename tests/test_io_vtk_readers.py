"""The VTK-readers plugin (plugins/volviz-vtk-readers) through ``volviz.io.read``: every file of
../shared/data/ecosystem and small multiblock / parallel / Tecplot / AVS UCD files written here, each checked against
VTK's own reader run directly (kind, sizes, array names, exact values, time steps), and bad files."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv
import vtk
from vtkmodules.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from volviz.model import CurvilinearGrid, RegularVolume, TimeSeries, UnstructuredMesh
from volviz_vtk_readers import list_blocks

from conftest import data_file

CAVITY_TIMES = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5]


def _arrays(attributes) -> dict[str, np.ndarray]:
    return {attributes.GetArrayName(i): vtk_to_numpy(attributes.GetArray(i))
            for i in range(attributes.GetNumberOfArrays()) if attributes.GetArray(i) is not None}


def _assert_same(mesh, ref) -> None:
    """A volviz dataset holds exactly the points and arrays of VTK's data set ``ref`` (one cell type: no permutation)."""
    assert mesh.n_points == ref.GetNumberOfPoints() and mesh.n_cells == ref.GetNumberOfCells()
    ref_points, ref_cells = _arrays(ref.GetPointData()), _arrays(ref.GetCellData())
    assert set(mesh.point_data) == set(ref_points) and set(mesh.cell_data) == set(ref_cells)
    for name, values in ref_points.items():
        np.testing.assert_array_equal(np.asarray(mesh.point_data[name]).reshape(values.shape, order="F"), values)
    for name, values in ref_cells.items():
        np.testing.assert_array_equal(np.asarray(mesh.cell_data[name]).reshape(values.shape, order="F"), values)


def _direct(cls: str, path, *switches, time: float | None = None):
    """VTK's reader ``cls`` run on ``path`` directly: the information pass, the ``switches`` (method names such as
    ``"EnableAllCellArrays"``, or ``(name, *args)``), then the data (of ``time``); returns the reader's output."""
    reader = getattr(vtk, cls)()
    reader.SetFileName(str(path))
    reader.UpdateInformation()
    for switch in switches:
        name, *args = (switch,) if isinstance(switch, str) else switch
        getattr(reader, name)(*args)
    reader.Update() if time is None else reader.UpdateTimeStep(time)
    return reader.GetOutput()


def _leaf(obj, *path: int):
    for i in path:
        obj = obj.GetBlock(i)
    return obj


def test_exodus_all_variables_merged_blocks():
    path = data_file("ecosystem/disk_out_ref.ex2")
    mesh = vio.read(path)
    block = _leaf(_direct("vtkExodusIIReader", path, ("SetAllArrayStatus", vtk.vtkExodusIIReader.NODAL, 1)), 0, 0)
    assert isinstance(mesh, UnstructuredMesh) and (mesh.n_points, mesh.n_cells) == (8499, 7472)
    assert list(mesh.point_data) == ["Temp", "V", "Pres", "AsH3", "GaMe3", "CH4", "H2"]
    assert mesh.point_data["V"].shape == (8499, 3)
    _assert_same(mesh, block)
    np.testing.assert_array_equal(mesh.points, vtk_to_numpy(block.GetPoints().GetData()))
    assert list_blocks(path) == ["Unnamed block ID: 1"]
    assert vio.read(path, blocks=["Unnamed block ID: 1"]).n_cells == 7472
    with pytest.raises(vio.ReadError, match=r"disk_out_ref\.ex2: no block named 'nope'; the file's blocks are: "
                                            r"Unnamed block ID: 1"):
        vio.read(path, blocks=["nope"])


def test_vtu_with_only_a_vector_array():
    path = data_file("ecosystem/notch_disp.vtu")
    mesh = vio.read(path)
    ref = _direct("vtkXMLUnstructuredGridReader", path)
    assert list(mesh.point_data) == ["Nodal Displacement"] and mesh.point_data["Nodal Displacement"].shape[1] == 3
    np.testing.assert_array_equal(mesh.point_data["Nodal Displacement"],
                                  vtk_to_numpy(ref.GetPointData().GetArray("Nodal Displacement")))


@pytest.mark.parametrize("name", ["openfoam-cavity", "openfoam-cavity/case.foam"])
def test_openfoam_case_folder_and_foam_file_time_series(name):
    path = data_file(f"ecosystem/{name}")
    series = vio.read(path)
    assert isinstance(series, TimeSeries) and series.times.tolist() == CAVITY_TIMES
    for k in (0, 3, 5):
        ref = _direct("vtkOpenFOAMReader", data_file("ecosystem/openfoam-cavity/case.foam"), "EnableAllCellArrays",
                      time=CAVITY_TIMES[k])
        frame = series.frame(k)
        assert isinstance(frame, UnstructuredMesh) and (frame.n_points, frame.n_cells) == (882, 400)
        assert set(frame.point_data) == {"U", "p"} and set(frame.cell_data) == {"U", "p"}
        _assert_same(frame, _leaf(ref, 0))
    assert not np.array_equal(series.frame(5).point_data["p"], series.frame(1).point_data["p"])
    assert list_blocks(path) == ["internalMesh", "patch/movingWall", "patch/fixedWalls", "patch/frontAndBack"]
    lid = vio.read(path, blocks=["patch/movingWall"], time_index=2)
    assert isinstance(lid, UnstructuredMesh) and lid.n_cells == 20


def test_netcdf_curvilinear_grid_cell_variable():
    path = data_file("ecosystem/sampleCurveGrid4.nc")
    grid = vio.read(path)
    out = _direct("vtkNetCDFCFReader", path, "ReplaceFillValueWithNanOn")
    assert isinstance(grid, CurvilinearGrid) and grid.dimensions == (49, 33, 1)
    assert list(grid.cell_data) == ["sample"] and grid.cell_data["sample"].shape == (48, 32, 1)
    np.testing.assert_array_equal(grid.cell_data["sample"].ravel(order="F"),
                                  vtk_to_numpy(out.GetCellData().GetArray("sample")))
    np.testing.assert_array_equal(grid.points.reshape(-1, 3, order="F"), vtk_to_numpy(out.GetPoints().GetData()))


def test_netcdf_ocean_field_24_months_with_land_as_nan():
    path = data_file("ecosystem/tos_O1_2001-2002.nc")
    with pytest.warns(vio.NonFiniteWarning, match="9510 NaN"):
        series = vio.read(path)
    assert isinstance(series, TimeSeries) and len(series) == 24
    assert series.times[:3].tolist() == [15.0, 45.0, 75.0]
    ref = _direct("vtkNetCDFCFReader", path, "ReplaceFillValueWithNanOn", time=series.times[7])
    with pytest.warns(vio.NonFiniteWarning):
        frame = series.frame(7)
    assert isinstance(frame, CurvilinearGrid) and frame.dimensions == (181, 171, 1)
    expected = vtk_to_numpy(ref.GetCellData().GetArray("tos"))
    np.testing.assert_array_equal(frame.cell_data["tos"].ravel(order="F"), expected)
    assert np.isnan(expected).sum() == 9510 and np.nanmax(expected) < 400  # land is NaN, not the 1e20 fill value
    np.testing.assert_allclose(np.linalg.norm(frame.points.reshape(-1, 3), axis=1), 1.0, atol=1e-12)  # on the sphere
    with pytest.warns(vio.NonFiniteWarning):
        flat = vio.read(path, spherical=False, time_index=7)
    assert isinstance(flat, RegularVolume) and flat.dimensions == (180, 170, 1)
    np.testing.assert_array_equal(flat.arrays["tos"].ravel(order="F"), expected)


def test_cgns_zones_merged_or_one_zone_structured():
    path = data_file("ecosystem/sqnz_s.adf.cgns")
    zones = _direct("vtkCGNSReader", path, "EnableAllCellArrays").GetBlock(0)
    merged = vio.read(path)
    assert isinstance(merged, UnstructuredMesh)
    assert merged.n_points == sum(zones.GetBlock(i).GetNumberOfPoints() for i in range(12)) == 15228
    assert merged.n_cells == 11264 and set(merged.cell_data) == {"Density", "Momentum", "EnergyStagnationDensity"}
    np.testing.assert_array_equal(
        merged.cell_data["Density"],
        np.concatenate([vtk_to_numpy(zones.GetBlock(i).GetCellData().GetArray("Density")) for i in range(12)]))
    blocks = list_blocks(path)
    assert len(blocks) == 12 and blocks[0] == "SQNZ/dom1_1_1_1"
    zone = vio.read(path, blocks=["dom1_3_1_1"])
    assert isinstance(zone, CurvilinearGrid) and zone.dimensions == (17, 9, 9)
    np.testing.assert_array_equal(zone.cell_data["Momentum"].reshape(-1, 3, order="F"),
                                  vtk_to_numpy(zones.GetBlock(2).GetCellData().GetArray("Momentum")))


# ---------------------------------------------------------------- files written here


def _beam() -> pv.UnstructuredGrid:
    grid = pv.examples.load_hexbeam()
    grid.point_data["height"] = grid.points[:, 2].copy()
    grid.point_data["disp"] = grid.points * 0.5
    grid.cell_data["id"] = np.arange(grid.n_cells, dtype=np.float64)
    return grid


def _write(writer, path, data, **settings):
    writer.SetFileName(str(path))
    writer.SetInputData(data)
    for key, value in settings.items():
        getattr(writer, f"Set{key}")(value)
    assert writer.Write() == 1
    return path


def test_vtm_blocks_merged_or_chosen(tmp_path):
    beam, image = _beam(), pv.ImageData(dimensions=(4, 3, 2))
    image.point_data["height"] = np.arange(24, dtype=np.float64)
    mb = vtk.vtkMultiBlockDataSet()
    for i, (name, block) in enumerate((("beam", beam), ("box", image.cast_to_unstructured_grid()))):
        mb.SetBlock(i, block)
        mb.GetMetaData(i).Set(vtk.vtkCompositeDataSet.NAME(), name)
    path = _write(vtk.vtkXMLMultiBlockDataWriter(), tmp_path / "two.vtm", mb)
    merged = vio.read(path)
    assert isinstance(merged, UnstructuredMesh) and merged.n_points == beam.n_points + 24
    np.testing.assert_array_equal(merged.point_data["height"], np.concatenate([beam["height"], image["height"]]))
    assert list_blocks(path) == ["beam", "box"]
    one = vio.read(path, blocks="beam")
    _assert_same(one, beam)


def test_vtpd_partitioned_collection(tmp_path):
    beam = _beam()
    collection = vtk.vtkPartitionedDataSetCollection()
    collection.SetPartition(0, 0, beam)
    collection.GetMetaData(0).Set(vtk.vtkCompositeDataSet.NAME(), "beam")
    path = _write(vtk.vtkXMLPartitionedDataSetCollectionWriter(), tmp_path / "c.vtpd", collection)
    mesh = vio.read(path)
    _assert_same(mesh, beam)
    assert list_blocks(path) == ["beam"]


def test_pvtu_and_pvti_pieces_joined(tmp_path):
    beam = _beam()
    pieces = vtk.vtkExtractUnstructuredGridPiece()  # hands each piece the writer asks for its part of the beam
    pieces.SetInputData(beam)
    writer = vtk.vtkXMLPUnstructuredGridWriter()
    writer.SetInputConnection(pieces.GetOutputPort())
    writer.SetFileName(str(tmp_path / "beam.pvtu"))
    writer.SetNumberOfPieces(2)
    writer.SetStartPiece(0)
    writer.SetEndPiece(1)
    assert writer.Write() == 1
    path = tmp_path / "beam.pvtu"
    assert len(list(tmp_path.glob("beam/*.vtu")) + list(tmp_path.glob("beam_*.vtu"))) == 2
    mesh = vio.read(path)
    assert mesh.n_cells == beam.n_cells
    _assert_same(mesh, _direct("vtkXMLPUnstructuredGridReader", path))
    image = pv.ImageData(dimensions=(6, 5, 4), spacing=(0.5, 1, 2), origin=(1, 2, 3))
    image.point_data["f"] = np.arange(120, dtype=np.float32) ** 2
    path = _write(vtk.vtkXMLPImageDataWriter(), tmp_path / "img.pvti", image, NumberOfPieces=2, StartPiece=0,
                  EndPiece=1)
    vol = vio.read(path)
    assert isinstance(vol, RegularVolume) and vol.dimensions == (6, 5, 4) and vol.spacing == (0.5, 1, 2)
    np.testing.assert_array_equal(vol.data.ravel(order="F"), image.point_data["f"])


TECPLOT = """TITLE = "two cells"
VARIABLES = "X" "Y" "Z" "T"
ZONE T="hex", N=12, E=2, F=FEPOINT, ET=BRICK
0 0 0 1
1 0 0 2
2 0 0 3
0 1 0 4
1 1 0 5
2 1 0 6
0 0 1 7
1 0 1 8
2 0 1 9
0 1 1 10
1 1 1 11
2 1 1 12
1 2 5 4 7 8 11 10
2 3 6 5 8 9 12 11
"""


def test_tecplot_ascii_sniffed_from_dat(tmp_path):
    path = tmp_path / "cells.dat"
    path.write_text(TECPLOT)
    assert vio.format_of(path, {}) == "tecplot"
    mesh = vio.read(path)
    assert (mesh.n_points, mesh.n_cells) == (12, 2)
    _assert_same(mesh, _leaf(_direct("vtkTecplotReader", path), 0))
    np.testing.assert_array_equal(mesh.point_data["T"], np.arange(1, 13))
    assert list_blocks(path) == ["hex"]


AVS_UCD = """# AVS UCD: two tetrahedra
5 2 1 1 0
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1
1 1 tet 1 2 3 4
2 1 tet 2 3 4 5
1 1
temperature, K
1 10.5
2 11.5
3 12.5
4 13.5
5 14.5
1 1
pressure, Pa
1 100
2 200
"""


def test_avs_ucd_told_from_abaqus_by_content(tmp_path):
    path = tmp_path / "tets.inp"
    path.write_text(AVS_UCD)
    mesh = vio.read(path)
    assert vio.format_of(path, {}) == "avs-ucd" and (mesh.n_points, mesh.n_cells) == (5, 2)
    _assert_same(mesh, _direct("vtkAVSucdReader", path))
    np.testing.assert_array_equal(mesh.point_data["temperature"], [10.5, 11.5, 12.5, 13.5, 14.5])
    abaqus = tmp_path / "abaqus.inp"
    abaqus.write_text("*HEADING\nabaqus\n*NODE\n1, 0, 0, 0\n")
    assert vio.format_of(abaqus, {}) == "meshio"


# ---------------------------------------------------------------- bad files


def test_netcdf_that_is_text(tmp_path):
    path = tmp_path / "notes.nc"
    path.write_text("these are my notes, not a netCDF file\n")
    with pytest.raises(vio.ReadError, match=r"notes\.nc: not a netCDF file: its content is text"):
        vio.read(path)


def test_openfoam_folder_without_a_case(tmp_path):
    case = tmp_path / "empty.foam"
    case.mkdir()
    with pytest.raises(vio.ReadError, match=r"empty\.foam: is a directory, not a file, and not a folder volviz "
                                            r"opens: .*OpenFOAM case \(holding system/controlDict\)"):
        vio.read(case)
    (case / "case.foam").write_text("")
    with pytest.raises(vio.ReadError, match=r"case\.foam: is not inside an OpenFOAM case: .*holds no "
                                            r"system/controlDict"):
        vio.read(case / "case.foam")


@pytest.mark.parametrize("keep", [100, 5000, 400000])
def test_truncated_exodus(tmp_path, keep):
    path = tmp_path / "cut.ex2"
    path.write_bytes(data_file("ecosystem/disk_out_ref.ex2").read_bytes()[:keep])
    with pytest.raises(vio.ReadError, match=r"cut\.ex2: Exodus II: the netCDF header .*truncated"):
        vio.read(path)


def test_exodus_name_with_text_content(tmp_path):
    path = tmp_path / "mesh.exo"
    path.write_text("hello")
    with pytest.raises(vio.ReadError, match=r"mesh\.exo: not a Exodus II file: its content is text"):
        vio.read(path)


def test_ensight_gold_case_written_by_vtk(tmp_path):
    """An EnSight Gold case (VTK's own writer; no sample file ships with the shared data) against VTK's reader."""
    beam = _beam()
    beam.cell_data["BlockId"] = np.ones(beam.n_cells, dtype=np.int32)   # the part each cell belongs to
    writer = vtk.vtkEnSightWriter()
    writer.SetInputData(beam)
    writer.SetPath(str(tmp_path) + "/")
    writer.SetBaseName("beam")
    writer.SetTimeStep(0)
    writer.SetNumberOfBlocks(1)
    writer.Write()
    writer.WriteCaseFile(1)
    case = tmp_path / "beam.0.case"
    reader = vtk.vtkGenericEnSightReader()
    reader.SetCaseFileName(str(case))
    reader.Update()
    ref = _leaf(reader.GetOutput(), 0)
    mesh = vio.read(case)
    assert isinstance(mesh, UnstructuredMesh) and [(t, c.shape) for t, c in mesh.cells] == [(12, (40, 8))]
    _assert_same(mesh, ref)
    assert {"height_n", "disp_n"} <= set(mesh.point_data)                # EnSight names per-node variables so
    np.testing.assert_allclose(mesh.point_data["height_n"], beam.point_data["height"], rtol=1e-6)


# -- EnSight: the case and the files it names checked before VTK's reader (issue #32, ensightcheck) ------------------
def _ensight_case(folder, case: str | None = None):
    """The bench's EnSight Gold ASCII seed (one part of 8 nodes and 5 tetra4, a scalar per node), its case file
    replaced by ``case`` when given."""
    from volviz.bench.robustness_formats import _ensight

    _ensight(folder)
    if case is not None:
        (folder / "mesh.case").write_text(case)
    return folder / "mesh.case"


def _ensight_refusal(path) -> str:
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    return str(info.value)


def test_ensight_case_cut_in_a_section_name_refused_naming_the_line(tmp_path):
    """VTK's reader looped to the 10 s time limit on this case file (the campaign's slow refusals)."""
    case = _ensight_case(tmp_path)
    case.write_bytes(case.read_bytes()[:58])
    assert _ensight_refusal(case) == (f"{case}: line 7 of the case file ('VARIA') is neither a section nor a "
                                      "'key: value' line")


def test_ensight_time_values_against_number_of_steps(tmp_path):
    case = _ensight_case(tmp_path, "FORMAT\ntype: ensight gold\nGEOMETRY\nmodel: 1 mesh.geo\nTIME\ntime set: 1\n"
                                   "number of steps: 3\ntime values: 0.0 0.5\n")
    assert _ensight_refusal(case) == f"{case}: time set 1: 'number of steps' is 3 but 'time values' holds 2 values"


def test_ensight_wildcard_steps_each_checked_then_read_as_a_series(tmp_path):
    case = _ensight_case(tmp_path, "FORMAT\ntype: ensight gold\nGEOMETRY\nmodel: mesh.geo\nVARIABLE\n"
                                   "scalar per node: 1 temperature temp.scl**\nTIME\ntime set: 1\n"
                                   "number of steps: 2\nfilename start number: 0\nfilename increment: 1\n"
                                   "time values: 0.0 1.0\n")
    (tmp_path / "temp.scl00").write_bytes((tmp_path / "temp.scl").read_bytes())
    assert _ensight_refusal(case) == (f"{case}: the variable file temp.scl01 (VARIABLE scalar per node "
                                      "'temp.scl**') does not exist")
    (tmp_path / "temp.scl01").write_text((tmp_path / "temp.scl").read_text().replace("0.00000e+00", "1.00000e+01"))
    series = vio.read(case)                                 # both steps there: read as VTK reads them
    assert isinstance(series, TimeSeries) and list(series.times) == [0.0, 1.0]
    first, second = series.frame(0), series.frame(1)
    assert first.point_data["temperature"][0] == 0.0 and second.point_data["temperature"][0] == 10.0


def test_ensight_variable_cut_short_refused_naming_the_part(tmp_path):
    """VTK's reader read the 8 node values of this file cut after 5 as other values."""
    case = _ensight_case(tmp_path)
    scl = tmp_path / "temp.scl"
    scl.write_bytes(scl.read_bytes()[:114])
    assert _ensight_refusal(case) == (f"{scl}: part 1's coordinates (8 values of the geometry's counts) needs 8 lines "
                                      "of values but the file holds 6 more: the file is truncated or the count is "
                                      "wrong")


def test_ensight_geometry_node_count_against_its_lines(tmp_path):
    case = _ensight_case(tmp_path)
    geo = tmp_path / "mesh.geo"
    geo.write_text(geo.read_text().replace("coordinates\n         8\n", "coordinates\n         7\n"))
    assert _ensight_refusal(case) == (f"{geo}: line 31 is '5.00000e-01' where an element type or 'part' should be: "
                                      "a count before it is wrong (part 1 has 7 nodes)")


def test_ensight_c_binary_geometry_cut_refused_naming_the_elements(tmp_path):
    """A C Binary geometry (VTK's own writer) cut inside its hexa8 connectivity."""
    writer = vtk.vtkEnSightWriter()
    beam = _beam()
    beam.cell_data["BlockId"] = np.ones(beam.n_cells, dtype=np.int32)
    writer.SetInputData(beam)
    writer.SetPath(str(tmp_path) + "/")
    writer.SetBaseName("beam")
    writer.SetNumberOfBlocks(1)
    writer.Write()
    writer.WriteCaseFile(1)
    geo = tmp_path / "beam.0.00000.geo"
    geo.write_bytes(geo.read_bytes()[:-100])
    assert _ensight_refusal(tmp_path / "beam.0.case") == (
        f"{geo}: part 1's 40 hexa8 elements needs 1440 bytes but the file holds 1340 more: the file is truncated "
        "or the count is wrong")


# -- AVS UCD: the header's counts against the file before VTK's reader (issue #32, avscheck) ------------------------
def _avs_tets(folder):
    """The bench's AVS UCD seed written by meshio: 8 nodes, 5 tets, one value per node and per cell."""
    from volviz.bench.robustness_formats import _avs

    _avs(folder, False)
    return folder / "mesh.inp"


@pytest.mark.parametrize("edit, message", [
    # the campaign's cut at byte 175 of 553, within the second cell line: VTK's reader read it as other cells
    (lambda data: data[:175], "line 12 ('2 0 tet 2') is not cell 2 of 5 (id, material, type and its nodes) that the "
                              "header's count needs"),
    (lambda data: data.replace(b"8 5 1 1 0", b"8 6 1 1 0"),
     "line 16 ('1 1') is not cell 6 of 6 (id, material, type and its nodes) that the header's count needs"),
    (lambda data: data.replace(b"8 5 1 1 0", b"8 5 2 1 0"),
     "line 16: the node data's component sizes add up to 1 but the header says 2 node values"),
], ids=["cut-in-cells", "cell-count", "node-values"])
def test_avs_ucd_counts_against_the_lines_refused_naming_the_line(tmp_path, edit, message):
    path = _avs_tets(tmp_path)
    path.write_bytes(edit(path.read_bytes()))
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    assert str(info.value) == f"{path}: {message}"


def test_avs_ucd_last_line_without_its_end_is_a_warning(tmp_path):
    path = _avs_tets(tmp_path)
    path.write_bytes(path.read_bytes()[:-1])
    with pytest.warns(vio.ReadWarning) as record:
        mesh = vio.read(path)
    assert mesh.n_points == 8 and mesh.n_cells == 5
    assert [str(w.message) for w in record if issubclass(w.category, vio.ReadWarning)] == [
        f"{path}: the file does not end with a line end: line 32, its last, may be cut short (a value of fewer "
        "digits)"]


def _binary_ucd() -> bytes:
    """A binary AVS UCD tetrahedron (VTK's binary layout: byte 7, six counts, cell records, connectivity, x, y, z)."""
    head = b"\x07" + np.array([4, 1, 0, 0, 0, 4], dtype="<i4").tobytes()
    cells = np.array([1, 1, 4, 4, 1, 2, 3, 4], dtype="<i4").tobytes()   # id, material, nodes, type (4: tet); nodes
    return head + cells + np.array([[0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype="<f4").tobytes()


def test_avs_ucd_binary_size_against_its_counts(tmp_path):
    path = tmp_path / "tet.inp"
    path.write_bytes(_binary_ucd())
    mesh = vio.read(path)
    assert (mesh.n_points, mesh.n_cells) == (4, 1)
    path.write_bytes(_binary_ucd()[:-4])
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    assert str(info.value) == (f"{path}: binary AVS UCD: the header's counts (nodes, cells, node fields, cell fields, "
                               "model fields, connectivity length) [4, 1, 0, 0, 0, 4] need 105 bytes but the file "
                               "holds 101: it is truncated or the header is wrong")


def test_ensight_case_cut_after_a_section_name_refused(tmp_path):
    """The campaign's cut at byte 62 of 100 ('VARIABLE' and its line end): VTK's reader read the geometry alone."""
    case = _ensight_case(tmp_path)
    case.write_bytes(case.read_bytes()[:62])
    assert _ensight_refusal(case) == (f"{case}: the case file's VARIABLE section is empty: the file is cut after its "
                                      "name or damaged")


def test_ensight_variable_file_without_a_part_refused(tmp_path):
    """The re-run's temp.scl cut at byte 12, inside its description line: VTK's reader read the mesh without it."""
    case = _ensight_case(tmp_path)
    scl = tmp_path / "temp.scl"
    scl.write_bytes(scl.read_bytes()[:12])
    assert _ensight_refusal(case) == (f"{scl}: holds its description line and no part (the geometry has parts [1]): "
                                      "the file is truncated")


def test_ensight_geometry_part_without_elements_refused(tmp_path):
    """The re-run's mesh.geo cut at byte 436, in its last coordinate: VTK's reader made 8 vertex cells of it."""
    case = _ensight_case(tmp_path)
    geo = tmp_path / "mesh.geo"
    geo.write_bytes(geo.read_bytes()[:436])
    assert _ensight_refusal(case) == f"{geo}: ends where part 1's first element type should be: the file is truncated"
