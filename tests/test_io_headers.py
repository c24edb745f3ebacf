"""Lying headers are refused before anything reads what they claim, and the valid files that were refused are read.

Each case is a real file built in tmp_path from the shared datasets (legacy and XML VTK, VTKHDF, SLC, PGM, DEM,
MetaImage): it must be refused with a ReadError naming the file and the problem, allocating less than 64 MB on the
way (tracemalloc sees Python's and NumPy's allocations; the checks run in this process, before VTK), or, for the
valid ones, read with the right values. VTK-backed reads run in this process (``isolate=False``): the checks refuse
every damaged file before VTK's reader sees it.
"""
from __future__ import annotations

import base64
import re
import shutil
import struct
import zlib

import numpy as np
import pytest

import volviz.io as vio
from conftest import data_file
from test_io_bad import allocation_budget

MB = 1 << 20


def refused(path, match: str, **options) -> vio.ReadError:
    """Read ``path`` in this process; it must fail with a ReadError naming the file and matching ``match``,
    allocating less than 64 MB."""
    with allocation_budget(64 * MB):
        with pytest.raises(vio.ReadError, match=match) as info:
            vio.read(path, isolate=False, **options)
    assert str(path) in str(info.value), "the message must name the file"
    return info.value


def write(path, data: bytes):
    path.write_bytes(data)
    return path


def refused_edits(tmp_path, data: bytes, suffix: str, edits) -> None:
    """Each ``(old, new, match)``: ``data`` with ``old`` replaced by ``new`` once is refused with ``match``."""
    for k, (old, new, match) in enumerate(edits):
        assert old in data, old
        refused(write(tmp_path / f"edit{k}{suffix}", data.replace(old, new, 1)), match)


# ---------------------------------------------------------------- legacy VTK


@pytest.fixture
def iron() -> bytes:
    return data_file("volumes/ironProt.vtk").read_bytes()


def legacy_grid(tmp_path, binary: bool) -> bytes:
    """A 30^3 unstructured grid with point, cell and field data, saved as legacy VTK (large enough that its
    CELL_DATA section lies past the first 64 KB)."""
    import pyvista as pv

    grid = pv.ImageData(dimensions=(30, 30, 30)).cast_to_unstructured_grid()
    grid.point_data["s"] = np.arange(grid.n_points, dtype=np.float32)
    grid.cell_data["c"] = np.arange(grid.n_cells, dtype=np.float32)
    grid.field_data["TIME"] = np.array([0.5])
    path = tmp_path / f"grid_{binary}.vtk"
    grid.save(path, binary=binary)
    return path.read_bytes()


def test_legacy_field_counts_are_checked_anywhere_in_the_file(tmp_path, iron):
    refused(write(tmp_path / "f1.vtk", iron + b"\nFIELD FieldData 999999\nA 1 1 float\n\0\0\0\0\n"),
            "FIELD announces 999999 arrays, more than the 17 bytes after it can hold")
    refused(write(tmp_path / "f2.vtk", iron + b"\nFIELD FieldData 1\nA 1 2147483647 float\n\0\0\0\0\n"),
            r"FIELD array 1 of 1 needs 8589934588 bytes")
    for binary in (True, False):
        grid = legacy_grid(tmp_path, binary)
        assert grid.count(b"FIELD FieldData 1\n") == 1
        # three arrays announced, one present: the walk reaches the POINTS line where array 2 should be
        refused(write(tmp_path / f"f3_{binary}.vtk", grid.replace(b"FIELD FieldData 1\n", b"FIELD FieldData 3\n")),
                "FIELD array 2 of 3: its line is text, not 'name components tuples type'")


@pytest.mark.parametrize("binary", [True, False])
def test_legacy_counts_past_the_first_64_kb(tmp_path, binary):
    grid = legacy_grid(tmp_path, binary)
    assert grid.index(b"CELL_DATA 24389") > 65536 and grid.index(b"POINT_DATA 27000") > 65536
    refused_edits(tmp_path, grid, ".vtk", [
        (b"CELL_DATA 24389", b"CELL_DATA 2147483647", r"CELL_DATA 2147483647 needs \d+ bytes .* only \d+ bytes remain"),
        (b"POINT_DATA 27000", b"POINT_DATA 27001", "POINT_DATA is 27001, but POINTS gives 27000"),
        (b"CELL_TYPES 24389", b"CELL_TYPES 24390", "CELL_TYPES is 24390, but CELLS gives 24389"),
        (b"POINTS 27000", b"POINTS 2147483648", "POINTS 2147483648 needs"),
    ])


def test_legacy_title_over_64_kb_is_read(tmp_path, iron):
    original = vio.read(data_file("volumes/ironProt.vtk"), isolate=False)
    long_title = write(tmp_path / "title.vtk", iron.replace(b"Iron protein", b"T" * 100_000, 1))
    volume = vio.read(long_title, isolate=False)
    np.testing.assert_array_equal(volume.data, original.data)
    refused(write(tmp_path / "lie.vtk", iron.replace(b"Iron protein", b"T" * 100_000, 1)
                  .replace(b"POINT_DATA 314432", b"POINT_DATA 3144320")), "POINT_DATA 3144320 needs")


def test_legacy_origin_spacing_and_model_errors(tmp_path, iron):
    refused_edits(tmp_path, iron, ".vtk", [
        (b"ORIGIN 0.0 0.0 0.0", b"ORIGIN nan 0.0 0.0", "ORIGIN must be three finite numbers"),
        (b"DIMENSIONS 68 68 68", b"DIMENSIONS 68 68 69", "DIMENSIONS .* claims 319056 points"),
        # zero spacing and cells naming missing points: VTK reads them, the model refuses them, the reader says so
        (b"ASPECT_RATIO 1.0 1.0 1.0", b"ASPECT_RATIO 0 0 0", "inconsistent: RegularVolume spacing must be positive"),
    ])
    mesh = (b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n"
            b"0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 99\nCELL_TYPES 1\n10\nPOINT_DATA 4\n"
            b"SCALARS s float 1\nLOOKUP_TABLE default\n0 1 2 3\n")
    refused(write(tmp_path / "c.vtk", mesh), "inconsistent: cell block of type 10 refers to points outside 0..3")


def test_legacy_texture_coordinates_are_read(tmp_path):
    """TEXTURE_COORDINATES is a point attribute, not the X_, Y_ or Z_COORDINATES of a rectilinear grid: read, and
    its dimension and count checked as an attribute's."""
    head = (b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nORIGIN 0 0 0\n"
            b"SPACING 1 1 1\nPOINT_DATA 8\nSCALARS s float 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n")
    volume = vio.read(write(tmp_path / "tc.vtk", head + b"TEXTURE_COORDINATES tc 2 float\n" + b"0 1 " * 8 + b"\n"),
                      isolate=False)
    np.testing.assert_array_equal(volume.data.ravel(order="F"), np.arange(8))
    refused(write(tmp_path / "tc4.vtk", head + b"TEXTURE_COORDINATES tc 4 float\n0\n"),
            "TEXTURE_COORDINATES of dimension 4")


def test_vtk_message_with_bytes_that_are_not_utf8(tmp_path, iron):
    err = refused(write(tmp_path / "u.vtk", iron.replace(b"SCALARS scalars", b"\xff\xfe\xfd scalars")),
                  "vtkDataSetReader failed")
    assert "\ufffd" not in str(err) and "\xff" not in str(err)


# ---------------------------------------------------------------- VTK XML


@pytest.fixture
def hydrogen() -> bytes:
    return data_file("volumes/hydrogen.vti").read_bytes()


def test_xml_image_markup_is_checked(tmp_path, hydrogen):
    refused_edits(tmp_path, hydrogen, ".vti", [
        (b'<Piece Extent="0 63 0 63 0 63"', b'<Piece Extent="63 0 0 63 0 63"', "lower bound above its upper bound"),
        (b'<Piece Extent="0 63 0 63 0 63"', b'<Piece Extent="0 64 0 63 0 63"', "outside the WholeExtent"),
        (b'WholeExtent="0 63 0 63 0 63"', b'WholeExtent="0 99999 0 99999 0 99999"',
         "claims 1000000000000000 points"),
        (b'byte_order="LittleEndian"', b'byte_order="BigEndian"', "header announces 536870912 blocks"),
        (b'byte_order="LittleEndian"', b'byte_order="Middle"', "byte_order is not one of LittleEndian, BigEndian"),
        (b'header_type="UInt32"', b'header_type="UInt128"', "header_type is not one of UInt32, UInt64"),
        (b'header_type="UInt32"', b'header_type="UInt64"', "header announces 140737488355360 blocks"),
        (b"vtkZLibDataCompressor", b"vtkFooCompressor", "compressor is not one of"),
        (b' compressor="vtkZLibDataCompressor"', b"", r"need 1048576 bytes \(1.0 MB\), more than the file"),
        (b'Origin="0 0 0"', b'Origin="nan 0 0"', "Origin must be 3 finite numbers"),
        (b'Name="probability_density" format', b'Name="probability_density" NumberOfComponents="3" format',
         "holds 1048576 bytes, but its tuples and components need 3145728"),
    ])


def test_xml_zlib_block_count_of_0xffffffff(tmp_path, hydrogen):
    start = re.search(rb'format="binary"[^>]*>\s*', hydrogen).end()
    blocks, block_size, last = struct.unpack("<3I", base64.b64decode(hydrogen[start:start + 16]))
    assert (blocks, block_size) == (32, 32768)
    bomb = hydrogen[:start] + base64.b64encode(struct.pack("<3I", 0xFFFFFFFF, block_size, last)) + \
        hydrogen[start + 16:]
    refused(write(tmp_path / "b.vti", bomb), "header announces 4294967295 blocks")


def test_xml_unstructured_counts_are_checked(tmp_path):
    refused_edits(tmp_path, data_file("ecosystem/notch_disp.vtu").read_bytes(), ".vtu", [
        (b'NumberOfComponents="3" format="binary"',
         b'NumberOfComponents="3" NumberOfTuples="2147483647" format="binary"',
         "NumberOfTuples is 2147483647, more than the file"),
        (b'NumberOfComponents="3" format="binary"', b'NumberOfComponents="3" NumberOfTuples="12716" format="binary"',
         "NumberOfTuples is 12716, but its piece needs 12717"),
        (b'NumberOfPoints="12717"', b'NumberOfPoints="12718"', "holds 305208 bytes, but its tuples and components"),
        (b'NumberOfPoints="12717"', b'NumberOfPoints="2147483647"', "NumberOfPoints is 2147483647, more than"),
        (b'NumberOfCells="2192"', b'NumberOfCells="2191"', "'types' in Cells: its binary data holds 2192 bytes"),
        (b'NumberOfCells="2192"', b'NumberOfCells="-1"', "NumberOfCells is -1, a negative count"),
        (b'format="binary"', b'format="packed"', "format is text, not ascii, binary or appended"),
    ])


def appended_grid(tmp_path, encode: bool):
    import pyvista as pv
    import vtk

    grid = pv.ImageData(dimensions=(8, 7, 6)).cast_to_unstructured_grid()
    grid.point_data["s"] = np.arange(grid.n_points, dtype=np.float64)
    grid.field_data["TIME"] = np.array([0.5, 1.5])
    writer = vtk.vtkXMLUnstructuredGridWriter()
    writer.SetInputData(grid)
    path = tmp_path / f"app_{encode}.vtu"
    writer.SetFileName(str(path))
    writer.SetDataModeToAppended()
    writer.SetEncodeAppendedData(encode)
    writer.SetCompressorTypeToNone()
    writer.Write()
    return grid, path


@pytest.mark.parametrize("encode", [False, True])
def test_xml_appended_offsets_and_headers(tmp_path, encode):
    grid, path = appended_grid(tmp_path, encode)
    mesh = vio.read(path, isolate=False)
    np.testing.assert_array_equal(mesh.point_data["s"], grid.point_data["s"])
    data = path.read_bytes()
    offsets = re.findall(rb'offset="(\d+)"', data)
    refused(write(tmp_path / "o.vtu", data.replace(b'offset="%s"' % offsets[-1], b'offset="99999999"', 1)),
            "appended offset 99999999 points past the end of the file")
    refused(write(tmp_path / "t.vtu", data.replace(b'NumberOfTuples="2"', b'NumberOfTuples="2000"', 1)),
            "its binary data holds 16 bytes, but its tuples and components need 16000")


def test_valid_xml_variants_are_read(tmp_path):
    """Every data mode, compressor and header type VTK writes passes the checks and reads the same values."""
    import pyvista as pv
    import vtk

    image = pv.ImageData(dimensions=(9, 8, 7), spacing=(0.5, 1, 2))
    image.point_data["s"] = np.arange(image.n_points, dtype=np.float32) ** 0.5
    for mode in ("Ascii", "Binary", "Appended"):
        for compressor in ("None", "ZLib", "LZ4", "LZMA"):
            for header in ("UInt32", "UInt64"):
                writer = vtk.vtkXMLImageDataWriter()
                writer.SetInputData(image)
                path = tmp_path / f"{mode}_{compressor}_{header}.vti"
                writer.SetFileName(str(path))
                getattr(writer, f"SetDataModeTo{mode}")()
                getattr(writer, f"SetCompressorTypeTo{compressor}")()
                getattr(writer, f"SetHeaderTypeTo{header}")()
                writer.SetBlockSize(256)
                writer.Write()
                volume = vio.read(path, isolate=False)
                np.testing.assert_allclose(volume.data.ravel(order="F"), image.point_data["s"], rtol=1e-6)


# ---------------------------------------------------------------- VTKHDF


def damaged_hdf(tmp_path, name: str, dataset: str, index, value):
    import h5py

    path = tmp_path / f"{name}.vtkhdf"
    shutil.copy(data_file("series/warping_spheres.vtkhdf"), path)
    with h5py.File(path, "r+") as f:
        ds = f["VTKHDF"][dataset]
        values = ds[()]
        values[index] = value
        ds[...] = values
    return path


@pytest.mark.parametrize("dataset,index,value,match", [
    ("Polygons/NumberOfCells", 0, -1, "Polygons/NumberOfCells holds a negative count"),
    ("Polygons/NumberOfCells", 0, 10**9, "Polygons/Offsets: step 0 reaches row 1000001682, but it has 3362 rows"),
    ("Steps/NumberOfParts", 3, 10**9, "step 3 uses parts 6 to 1000000005, but the file describes 200 parts"),
    ("NumberOfPoints", 199, 843, "Points: step 99 reaches row 168401, but it has 168400 rows"),
    ("Polygons/NumberOfConnectivityIds", 0, 5041, "Polygons/Connectivity: step 0 reaches row 10081"),
    ("Steps/PartOffsets", 10, 199, "step 10 uses parts 199 to 200"),
])
def test_vtkhdf_counts_against_dataset_shapes(tmp_path, dataset, index, value, match):
    refused(damaged_hdf(tmp_path, "d", dataset, index, value), match)


def test_vtkhdf_static_grid_counts(tmp_path):
    import h5py
    import pyvista as pv
    import vtk

    grid = pv.ImageData(dimensions=(5, 5, 5)).cast_to_unstructured_grid()
    grid.point_data["s"] = np.arange(grid.n_points, dtype=np.float64)
    writer = vtk.vtkHDFWriter()
    writer.SetInputData(grid)
    path = tmp_path / "g.vtkhdf"
    writer.SetFileName(str(path))
    writer.Write()
    np.testing.assert_array_equal(vio.read(path, isolate=False).point_data["s"], grid.point_data["s"])
    for name, value, match in (("NumberOfCells", -1, "NumberOfCells holds a negative count"),
                               ("NumberOfCells", 65, "Types has 64 rows, but the counts add up to 65"),
                               ("NumberOfPoints", 10**12, "NumberOfPoints holds the count 1000000000000, more")):
        bad = tmp_path / f"bad_{name}_{value}.vtkhdf"
        shutil.copy(path, bad)
        with h5py.File(bad, "r+") as f:
            f["VTKHDF"][name][0] = value
        refused(bad, match)


def test_damaged_hdf5_metadata_is_a_read_error(tmp_path):
    """Bytes flipped in the HDF5 metadata make h5py raise its own exceptions; each is a ReadError."""
    data = bytearray(data_file("series/warping_spheres.vtkhdf").read_bytes())
    rng = np.random.default_rng(7)
    kinds = set()
    for k in range(40):
        damaged = bytearray(data)
        for pos in rng.integers(8, 6000, size=4):
            damaged[pos] ^= 0xFF
        path = write(tmp_path / f"m{k}.vtkhdf", bytes(damaged))
        try:
            vio.read(path, isolate=False)
        except vio.ReadError as exc:
            assert str(path) in str(exc)
            kinds.add(exc.problem.split(":")[0][:40])
    assert any("HDF5 library could not read" in k for k in kinds)


# ---------------------------------------------------------------- volviz's own parsers


def test_slc_with_a_wrong_x_size_is_refused(tmp_path):
    data = data_file("volumes/neghip.slc").read_bytes()
    assert data.startswith(b"11111\n66 66 66 8")
    refused(write(tmp_path / "x.slc", data.replace(b"66 66 66 8", b"67 66 66 8", 1)),
            "run-length code of slice 0 decodes to 4356 of the 4422 voxels of the header's 67x66 slice")
    refused(write(tmp_path / "t.slc", data + b"\x01\x02"), "2 bytes follow the last of the header's 66 slices")
    assert vio.read(data_file("volumes/embryo.slc")).data.shape == (256, 256, 256)  # one voxel short per slice


def test_pgm_size_must_match_exactly(tmp_path):
    original = vio.read(data_file("yukon/Yukon.fogmap1.pgm"))
    values = original.data
    ascii_pgm = b"P2\n64 64\n255\n" + b"\n".join(b" ".join(b"%d" % v for v in row) for row in values) + b"\n"
    np.testing.assert_array_equal(vio.read(write(tmp_path / "a.pgm", ascii_pgm)).data, values)
    refused(write(tmp_path / "p5.pgm", b"P5" + ascii_pgm[2:]), r"bytes follow the 64x64 P5 raster")
    raw = data_file("yukon/Yukon.fogmap1.pgm").read_bytes()
    refused(write(tmp_path / "tail.pgm", raw + b"\n"), "1 bytes follow the 64x64 P5 raster")
    refused(write(tmp_path / "extra.pgm", ascii_pgm + b"7\n"), "ASCII raster holds 4097 samples, the header needs 4096")


def test_pgm_with_long_comments_is_read(tmp_path):
    raw = data_file("yukon/Yukon.fogmap1.pgm").read_bytes()
    assert raw.startswith(b"P5\n64 64\n255\n")
    comment = b"# " + b"x" * 10_000 + b"\n"
    long = write(tmp_path / "c.pgm", b"P5\n" + comment * 3 + b"64 64\n" + comment + b"255\n" + raw[13:])
    np.testing.assert_array_equal(vio.read(long).data, vio.read(data_file("yukon/Yukon.fogmap1.pgm")).data)


def dem_bytes() -> bytes:
    return data_file("terrain/SainteHelens.dem").read_bytes()


def test_dem_truncated_at_a_record_boundary_is_refused(tmp_path):
    data = dem_bytes()
    starts = [p for p in range(1024, len(data), 1024) if re.match(rb"\s{5}1\s+\d+\s+\d+\s+1", data[p:p + 24])]
    assert len(starts) == 327
    refused(write(tmp_path / "t.dem", data[:starts[200]]), "DEM file ends after 200 of the header's 327 profiles")


def test_dem_whose_profile_count_is_less_than_its_profiles_is_refused(tmp_path):
    """Issue #32 (the full campaign's one DEM silent acceptance): the profile-columns field "   327" at byte 858
    read as "   214" (a longer number written over it shifted the record) read 214 of the 327 profiles as the whole
    terrain, the other 341,047 bytes ignored without a word. An accuracy record (type C, 1024 bytes) may follow."""
    data = dem_bytes()
    assert data[858:864] == b"   327"
    error = refused(write(tmp_path / "n.dem", data[:858] + b"   214" + data[864:]),
                    "DEM header gives 214 profile columns, but .* bytes of data follow the last of them")
    assert str(error).endswith("the header's count is less than the file holds")
    assert data[993472:].split()[:4] == [b"1", b"3", b"3", b"3"]   # the file's own accuracy record
    assert vio.read(write(tmp_path / "c.dem", data), isolate=False).data.shape == (466, 327)


def test_dem_with_huge_vertical_resolution_is_refused(tmp_path):
    data = bytearray(dem_bytes())
    assert data[840:852].strip() == b"0.100000E+01"
    data[840:852] = b"  0.1000E+309"[-12:]
    refused(write(tmp_path / "z.dem", bytes(data)), "DEM heights overflow")


def test_metaimage_claims(tmp_path):
    packed = zlib.compress(bytes(1000))
    refused(write(tmp_path / "o.mha", b"NDims = 3\nDimSize = 2097152 2097152 2097152\nElementType = MET_UCHAR\n"
                                      b"CompressedData = True\nElementDataFile = LOCAL\n" + packed),
            "more than its 17 compressed bytes can inflate to")
    refused(write(tmp_path / "n.mha", b"NDims = 3\nDimSize = 1 1 1\nOffset = nan 0 0\nElementType = MET_UCHAR\n"
                                      b"ElementDataFile = LOCAL\n\x07"), "MetaImage offset is nan, not a finite number")


# ---------------------------------------------------------------- messages quote no file contents


SECRET = b"TOP-SECRET-PASSPHRASE"


@pytest.mark.parametrize("name,content", [
    ("a.pvm", b"PVX " + SECRET), ("b.pvm", b"PVM\n" + SECRET + b" 1 1\n1\n"), ("c.pvm", b"PVM2\n1 1 1\n" + SECRET + b"\n1\n"),
    ("a.pgm", b"P9 " + SECRET), ("b.pgm", b"P5\n" + SECRET + b" 2\n255\n"),
    ("a.slc", b"11111\n" + SECRET), ("b.slc", SECRET),
    ("a.vtk", SECRET), ("b.vtk", b"# vtk DataFile Version 3.0\nt\n" + SECRET + b"\n"),
    ("a.vti", SECRET), ("a.vtkhdf", SECRET), ("a.dem", b" " * 528 + SECRET + b" " * 600),
    ("a.mha", SECRET + b"\nElementDataFile = LOCAL\n"), ("b.mha", b"NDims = 3\nDimSize = " + SECRET + b"\n"
                                                                   b"ElementDataFile = LOCAL\n"),
    ("c.mha", b"NDims = 3\nDimSize = 1 1 1\nElementType = " + SECRET + b"\nElementDataFile = LOCAL\n"),
    ("d.mha", b"NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\nElementDataFile = " + SECRET + b"%d\n"),
    ("a.bov", b"DATA_FILE: a.bov\nDATA_SIZE: 1 1 1\nDATA_FORMAT: " + SECRET + b"\n"),
    ("b.bov", b"DATA_FILE: b.bov\nDATA_SIZE: 1 " + SECRET + b" 1\nDATA_FORMAT: FLOAT\n"),
    ("a.pvd", b'<VTKFile type="Collection"><Collection><DataSet timestep="' + SECRET + b'" file="."/>'
              b"</Collection></VTKFile>"),
    ("a.cube", b"c\nc\n" + SECRET + b" 0 0 0\n1 1 0 0\n1 0 1 0\n1 0 0 1\n"),
    ("noext", SECRET + b"\x00\x01"), ("a.unknownext", SECRET),
])
def test_messages_do_not_quote_the_file(tmp_path, name, content):
    err = refused(write(tmp_path / name, content), ".")
    assert SECRET.decode() not in err.problem and SECRET[:8].decode() not in err.problem
