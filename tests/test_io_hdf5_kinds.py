"""Formats on HDF5 are told apart before the plain HDF5-arrays reader takes a file (``volviz.io.hdf5kind``): Fluent
CFF through vtkFLUENTCFFReader (compared with VTK's reader on ``ecosystem/fluent-room``), and small files made here in
the shapes of Fluent CFF, CGNS, Exodus, netCDF-4, VTKHDF and MAT v7.3, each holding a volume the arrays reader would
otherwise have shown."""
from __future__ import annotations

import shutil

import h5py
import numpy as np
import pytest
from vtk.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from conftest import data_file
from volviz.io.errors import ReadError, ReadWarning
from volviz.io.hdf5kind import hdf5_kind
from volviz.model import RegularVolume, UnstructuredMesh

VOLUME = np.arange(4 * 5 * 6, dtype=np.float32).reshape(4, 5, 6)
MAT_HEADER = (b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
              .ljust(116) + b"\0" * 8 + b"\x00\x02IM")


def _vtk_cff(case):
    import vtk

    reader = vtk.vtkFLUENTCFFReader()
    reader.SetFileName(str(case))
    reader.UpdateInformation()
    reader.EnableAllCellArrays()
    reader.Update()
    return reader.GetOutput().GetBlock(0)


def test_a_fluent_cff_case_and_its_data_file_read_as_vtk_reads_them():
    case = data_file("ecosystem/fluent-room/room.cas.h5")
    assert hdf5_kind(case) == "fluent-cff" and hdf5_kind(case.with_name("room.dat.h5")) == "fluent-cff"
    expected = _vtk_cff(case)
    cd = expected.GetCellData()
    names = sorted(cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays()))
    assert len(names) == 12 and all(n.startswith("SV_") for n in names)
    for opened in (case, case.with_name("room.dat.h5")):
        mesh = vio.read(opened)
        assert isinstance(mesh, UnstructuredMesh)
        assert (mesh.n_points, mesh.n_cells) == (4565, 4338)
        assert sorted(mesh.cell_data) == names
        np.testing.assert_array_equal(mesh.points, vtk_to_numpy(expected.GetPoints().GetData()))
        for name in ("SV_T", "SV_P", "SV_BF_V"):
            np.testing.assert_array_equal(mesh.cell_data[name], vtk_to_numpy(cd.GetArray(name)))
    assert float(mesh.cell_data["SV_T"].min()) == pytest.approx(283.148, abs=1e-3)
    from volviz_vtk_readers import list_blocks

    assert list_blocks(case) == ["block0"]  # its one cell zone, found by VTK's reader though the name says .h5


def test_fluent_cff_files_apart_or_misnamed_are_refused_or_read_as_the_mesh_with_a_warning(tmp_path):
    source = data_file("ecosystem/fluent-room")
    shutil.copy(source / "room.cas.h5", tmp_path / "solo.cas.h5")
    with pytest.warns(ReadWarning, match=r"solo.cas.h5: no data file solo.dat.h5 beside it: the mesh is shown"):
        mesh = vio.read(tmp_path / "solo.cas.h5", isolate=False)
    assert (mesh.n_cells, mesh.cell_data) == (4338, {})
    shutil.copy(source / "room.dat.h5", tmp_path / "alone.dat.h5")
    with pytest.raises(ReadError, match=r"alone.dat.h5: is Fluent CFF data .* its case file alone.cas.h5 is not "
                                        r"beside it; put alone.cas.h5 beside it and open that$"):
        vio.read(tmp_path / "alone.dat.h5")
    shutil.copy(source / "room.cas.h5", tmp_path / "renamed.h5")
    with pytest.raises(ReadError, match=r"renamed.h5: is a Fluent CFF case, .* rename it NAME.cas.h5"):
        vio.read(tmp_path / "renamed.h5")
    data = (source / "room.cas.h5").read_bytes()
    (tmp_path / "cut.cas.h5").write_bytes(data[:len(data) // 2])
    with pytest.raises(ReadError, match=r"cut.cas.h5: the HDF5 library could not read it .*truncated file"):
        vio.read(tmp_path / "cut.cas.h5")


def _room_pair(folder):
    source = data_file("ecosystem/fluent-room")
    for name in ("room.cas.h5", "room.dat.h5"):
        shutil.copyfile(source / name, folder / name)
    return folder / "room.cas.h5", folder / "room.dat.h5"


@pytest.mark.parametrize("cut, problem", [
    (20, "the file holds 20 bytes and ends inside its HDF5 superblock (the end-of-file address is at bytes 40 to "
         "48): it is truncated"),
    (8, "the file holds 8 bytes, fewer than an HDF5 superblock: it is truncated")])
def test_fluent_cff_data_file_cut_inside_its_superblock_refused_naming_it(tmp_path, cut, problem):
    """Issue #32: VTK's reader read the case alone, without a word, beside a data file cut in its first 48 bytes."""
    case, data = _room_pair(tmp_path)
    data.write_bytes(data.read_bytes()[:cut])
    with pytest.raises(ReadError) as info:
        vio.read(case)
    assert str(info.value) == f"{data}: {problem}"


def test_fluent_cff_cell_field_length_against_the_case_cells(tmp_path):
    case, data = _room_pair(tmp_path)
    with h5py.File(data, "r+", locking=False) as f:
        del f["results/1/phase-1/cells/SV_T/1"]
        f["results/1/phase-1/cells/SV_T/1"] = np.zeros(4337, np.float32)
    with pytest.raises(ReadError) as info:
        vio.read(case)
    assert str(info.value) == (f"{data}: cell field /results/1/phase-1/cells/SV_T holds 4337 values but the case "
                               "room.cas.h5 has 4338 cells")


def _volume_file(path, userblock: int = 0):
    f = h5py.File(path, "w", userblock_size=userblock) if userblock else h5py.File(path, "w")
    f["volume"] = VOLUME
    return f


def _shape(path, kind: str):
    """A file of plain arrays (a 4 x 5 x 6 volume) given the marks of ``kind``."""
    with _volume_file(path, 512 if kind == "matlab" else 0) as f:
        if kind == "fluent-cff":
            f.create_group("meshes/1/nodes")
            f.create_group("settings")
        elif kind == "fluent-cff-data":
            f.create_group("results/1/phase-1/cells")
            f.create_group("settings")
        elif kind == "cgns":
            f[" format"] = np.frombuffer(b"IEEE_LITTLE_32\0", np.int8)
            f[" hdf5version"] = np.zeros(33, np.int8)
        elif kind == "exodus":
            f.attrs["_NCProperties"] = np.bytes_("version=2,netcdf=4.9.2,hdf5=1.14.3")
            f.attrs["api_version"] = np.float32(8.1)
            f["coordx"] = np.zeros(3)
        elif kind == "netcdf":
            f["volume"].attrs["_Netcdf4Coordinates"] = np.array([0, 1, 2], np.int32)
        elif kind == "vtkhdf":
            f.create_group("VTKHDF")
        elif kind == "matlab":
            f["volume"].attrs["MATLAB_class"] = np.bytes_("single")
    if kind == "matlab":
        with open(path, "r+b") as fh:
            fh.write(MAT_HEADER)
    return path


KINDS = ["fluent-cff", "fluent-cff-data", "cgns", "exodus", "netcdf", "vtkhdf", "matlab"]


@pytest.mark.parametrize("kind", KINDS)
def test_each_format_on_hdf5_is_told_from_plain_arrays(tmp_path, kind):
    path = _shape(tmp_path / "made.h5", kind)
    assert hdf5_kind(path) == kind.replace("-data", "")
    try:
        result = vio.read(path)
    except ReadError as exc:
        assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)
        assert "plain" not in str(exc)
    else:  # read by the format's own reader: only MAT v7.3 is, in MATLAB's (r, c, s) layout
        assert kind == "matlab" and isinstance(result, RegularVolume)
        assert result.dimensions == (5, 6, 4)
        np.testing.assert_array_equal(result.data, np.transpose(VOLUME, (1, 2, 0)))
    plain = vio.read(_shape(tmp_path / "plain.h5", "none"))
    assert isinstance(plain, RegularVolume) and plain.dimensions == (6, 5, 4)


def test_lookalikes_stay_plain_arrays_and_dataset_still_reads_one_array(tmp_path):
    path = tmp_path / "lookalike.h5"
    with _volume_file(path) as f:
        f.create_group("meshes")            # a Fluent CFF case has /settings too
        f.create_group("results")
        f["format"] = np.zeros(3)           # CGNS's is " format", with its leading blank
        f.attrs["api_version"] = 8.0        # Exodus without netCDF-4's marks
    assert hdf5_kind(path) is None
    np.testing.assert_array_equal(vio.read(path).data, np.transpose(VOLUME, (2, 1, 0)))
    cff = _shape(tmp_path / "cff.h5", "fluent-cff")
    np.testing.assert_array_equal(vio.read(cff, dataset="/volume").data, np.transpose(VOLUME, (2, 1, 0)))


def test_a_vtkhdf_file_named_h5_is_read_as_vtk_data(tmp_path):
    import vtk

    source = vtk.vtkRTAnalyticSource()
    source.SetWholeExtent(0, 7, 0, 5, 0, 3)
    writer = vtk.vtkHDFWriter()
    writer.SetInputConnection(source.GetOutputPort())
    writer.SetFileName(str(tmp_path / "wavelet.h5"))
    writer.Write()
    assert hdf5_kind(tmp_path / "wavelet.h5") == "vtkhdf"
    volume = vio.read(tmp_path / "wavelet.h5")
    source.Update()
    expected = vtk_to_numpy(source.GetOutput().GetPointData().GetArray("RTData")).reshape(4, 6, 8)
    assert volume.dimensions == (8, 6, 4)
    np.testing.assert_allclose(volume.data, np.transpose(expected, (2, 1, 0)), rtol=1e-6)
