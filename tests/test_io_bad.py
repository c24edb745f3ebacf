"""Bad input: every reader raises volviz.io.ReadError naming the file and the problem, before any large
allocation (checked with tracemalloc, which sees numpy's buffers), for truncated files, wrong magic, headers
claiming more data than the file holds, zero/negative dimensions, NaN/Inf values, unreadable files and
directories."""
from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
import tracemalloc
import warnings
import zlib

import numpy as np
import pytest

import volviz.io as vio
from conftest import data_file

MB = 1 << 20


@contextlib.contextmanager
def allocation_budget(limit_bytes: int = 8 * MB):
    """Fail if the block allocates more than ``limit_bytes`` at peak (Python and numpy allocations)."""
    tracemalloc.start()
    try:
        yield
    finally:
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    assert peak < limit_bytes, f"peak allocation {peak / MB:.1f} MB"


def read_error(path, match: str, **options) -> vio.ReadError:
    with pytest.raises(vio.ReadError, match=match) as info:
        vio.read(path, **options)
    assert str(path) in str(info.value), "the message must name the file"
    return info.value


def truncated_copy(src, dst, fraction: float = 0.5):
    data = src.read_bytes()
    dst.write_bytes(data[: int(len(data) * fraction)])
    return dst


# ---------------------------------------------------------------- the error type


def test_read_error_names_file_and_problem():
    err = vio.ReadError("/x/y.pvm", "header claims 100000x100000x100000 voxels")
    assert str(err) == "/x/y.pvm: header claims 100000x100000x100000 voxels"
    assert err.path == "/x/y.pvm" and err.problem.startswith("header")
    import pickle

    assert str(pickle.loads(pickle.dumps(err))) == str(err)


# ---------------------------------------------------------------- truncated real files


@pytest.mark.parametrize("name,match", [
    ("storm/Storm.pvm-t01", "truncated"),
    ("volumes/neghip.slc", "slice|truncated|ends"),
    ("volumes/embryo.slc", "slice|truncated|ends"),
    ("yukon/Yukon.map.pgm", "truncated"),
    ("yukon/Yukon.texmap.ppm", "truncated"),
    ("terrain/SainteHelens.dem", "DEM profile"),
    ("volumes/hydrogen.vti", "vtkXMLImageDataReader failed|no closing </DataArray>|cut short"),
    ("volumes/ironProt.vtk", "failed|truncated|more values"),
    ("series/warping_spheres.vtkhdf", "HDF5|VTKHDF|failed"),
])
def test_truncated_real_files(tmp_path, name, match):
    src = data_file(name)
    dst = truncated_copy(src, tmp_path / src.name)
    read_error(dst, match)


def test_truncated_plot3d_and_metaimage(tmp_path):
    xyz = truncated_copy(data_file("bluntfin/bluntfinxyz.bin"), tmp_path / "bluntfinxyz.bin", 0.9)
    shutil.copy(data_file("bluntfin/bluntfinq.bin"), tmp_path / "bluntfinq.bin")
    read_error(xyz, "PLOT3D xyz header claims 1 block.s. of 40x32x32 points")
    shutil.copy(data_file("bluntfin/bluntfinxyz.bin"), xyz)
    truncated_copy(data_file("bluntfin/bluntfinq.bin"), tmp_path / "bluntfinq.bin", 0.9)
    with pytest.raises(vio.ReadError, match="bluntfinq.bin: PLOT3D q header claims"):
        vio.read(xyz)
    shutil.copy(data_file("volumes/HeadMRVolume.mhd"), tmp_path / "HeadMRVolume.mhd")
    truncated_copy(data_file("volumes/HeadMRVolume.raw"), tmp_path / "HeadMRVolume.raw")
    with pytest.raises(vio.ReadError, match=r"HeadMRVolume.mhd: data file \S+HeadMRVolume.raw: MetaImage 48x62x42 "
                                            r"MET_UCHAR data needs 124992"):
        vio.read(tmp_path / "HeadMRVolume.mhd")


def test_headsq_slice_of_wrong_size(tmp_path):
    for k in (1, 2, 3):
        shutil.copy(data_file(f"headsq/quarter.{k}"), tmp_path / f"quarter.{k}")
    truncated_copy(data_file("headsq/quarter.2"), tmp_path / "quarter.2")
    with pytest.raises(vio.ReadError, match=r"quarter\.2: 64x64 samples of 2 byte\(s\) need 8192 bytes"):
        vio.read_slice_stack(str(tmp_path / "quarter.%d"), (64, 64), "u2")


# ---------------------------------------------------------------- wrong magic


@pytest.mark.parametrize("name,content,match", [
    ("a.pvm", b"PVX\n2 2 2\n1\n" + bytes(8), "not a PVM file"),
    ("a.pgm", b"P9\n2 2\n255\n" + bytes(4), "not a PGM/PPM file"),
    ("a.pgm", b"P4\n2 2\n" + bytes(4), "PBM bitmaps"),
    ("a.slc", b"11112\n2 2 2 8\n1 1 1\n1 6 0 0\n0 0 X" + bytes(8), "magic number"),
    ("a.mhd", b"just some text\nwithout the data line\n", "not 'Key = Value'"),
    ("a.vtk", b"# not vtk\nhello\nASCII\nDATASET POLYDATA\n", "not a VTK legacy file"),
    ("a.vti", b"hello world", "not a VTK XML file"),
    ("a.vti", b'<?xml version="1.0"?>\n<VTKFile type="PolyData"></VTKFile>', "holds PolyData"),
    ("a.vtkhdf", b"not an hdf5 file at all", "not an HDF5"),
    ("a.dem", b"short", "DEM type A header is 5 bytes"),
    ("a.xyz", b"\xff" * 7, "not a PLOT3D xyz file"),
    ("a.msh", b"$NotGmsh\n", "meshio could not read it"),
    ("a.unknownext", b"\x00\x01\x02\x03", "unknown data format"),
    ("a.jpg", b"\xff\xd8\xff\xe0 not really a jpeg", "not a readable image"),
])
def test_wrong_magic(tmp_path, name, content, match):
    path = tmp_path / name
    path.write_bytes(content)
    read_error(path, match)


# ---------------------------------------------------------------- headers claiming more data than the file


def test_pvm_claiming_100000_cubed_fails_fast_without_allocating(tmp_path):
    path = tmp_path / "huge.pvm"
    path.write_bytes(b"PVM\n100000 100000 100000\n1\n" + bytes(18032))
    with allocation_budget():
        err = read_error(path, r"100000x100000x100000 voxels of 1 byte needs 1000000000000000 bytes \(1.0 PB\) "
                               r"but the file holds only 18032 bytes")
    assert "truncated" in err.problem


@pytest.mark.parametrize("name,content,match", [
    ("huge2.pvm", b"PVM2\n100000 100000 100000\n1 1 1\n2\n" + bytes(100), "needs 2000000000000000 bytes"),
    ("huge.pgm", b"P5\n100000 100000\n255\n" + bytes(100), "100000x100000 P5 raster"),
    ("huge.ppm", b"P3\n100000 100000\n255\n1 2 3\n", "ASCII raster"),
    ("huge.slc", b"11111\n100000 100000 100000 8\n1 1 1\n1 6 0 1\n0 0 X1 X\x00", "run-length coded"),
    ("huge0.slc", b"11111\n100000 100000 100000 8\n1 1 1\n1 6 0 0\n0 0 X\x00", "SLC header's 100000x"),
    ("huge.mha", b"NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n"
                 + bytes(100), "needs 4000000000000000 bytes"),
    ("huge.vtk", b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 "
                 b"100000\nPOINT_DATA 1000000000000000\nSCALARS s float\nLOOKUP_TABLE default\n" + bytes(64),
     "claims"),
    ("huge.vti", b'<?xml version="1.0"?>\n<VTKFile type="ImageData"><ImageData WholeExtent="0 99999 0 99999 0 '
                 b'99999" Origin="0 0 0" Spacing="1 1 1"></ImageData></VTKFile>', "WholeExtent"),
])
def test_headers_claiming_too_much_fail_before_allocating(tmp_path, name, content, match):
    path = tmp_path / name
    path.write_bytes(content)
    with allocation_budget():
        read_error(path, match)


def test_compressed_metaimage_bomb_is_bounded(tmp_path):
    packed = zlib.compress(bytes(50 * MB), 9)  # 50 MB of zeros in ~50 KB; the header asks for 8 bytes
    path = tmp_path / "bomb.mha"
    path.write_bytes(b"NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nCompressedData = True\n"
                     b"ElementDataFile = LOCAL\n" + packed)
    with allocation_budget(4 * MB):
        read_error(path, r"inflates to 9\+ bytes, the header needs 8")


def test_plot3d_and_dem_and_raw_claiming_too_much(tmp_path):
    xyz = tmp_path / "huge.xyz"
    xyz.write_bytes(np.array([100000, 100000, 100000], "<i4").tobytes() + bytes(1000))
    with allocation_budget():
        read_error(xyz, "100000x100000x100000 points, which needs 12000000000000012 bytes")
    dem = bytearray(data_file("terrain/SainteHelens.dem").read_bytes()[:4096])
    dem[816:852] = b"    0.30E-10    0.30E-10    0.10E+01"  # a 3e-11 m grid over the quadrangle
    (tmp_path / "tiny.dem").write_bytes(bytes(dem))
    with allocation_budget():
        read_error(tmp_path / "tiny.dem", "grid, which does not fit")
    raw = tmp_path / "v.raw"
    raw.write_bytes(bytes(100))
    with allocation_budget():
        with pytest.raises(vio.ReadError, match="need 4000000000000000 bytes"):
            vio.read_raw(raw, (100000, 100000, 100000), "f4")


# ---------------------------------------------------------------- zero / negative dimensions


@pytest.mark.parametrize("name,content,match", [
    ("z.pvm", b"PVM\n0 28 23\n1\n", "must all be positive"),
    ("n.pvm", b"PVM\n-5 28 23\n1\n", "must all be positive"),
    ("z.pgm", b"P5\n0 10\n255\n", "must all be positive"),
    ("n.pgm", b"P5\n-3 10\n255\n", "not a non-negative integer"),
    ("z.slc", b"11111\n4 0 4 8\n1 1 1\n1 6 0 0\n0 0 X", "must all be positive"),
    ("z.mha", b"NDims = 3\nDimSize = 4 0 4\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n", "positive"),
    ("n.mha", b"NDims = 3\nDimSize = 4 -2 4\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n", "positive"),
    ("z.vtk", b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 0 3 3\n", "positive"),
    ("z.vti", b'<?xml version="1.0"?>\n<VTKFile type="ImageData"><ImageData WholeExtent="0 3 5 2 0 3">'
              b"</ImageData></VTKFile>", "lower bound above its upper bound"),
    ("z.xyz", np.array([0, 3, 3], "<i4").tobytes() + bytes(64), "not a PLOT3D xyz file"),
    ("n.xyz", np.array([-4, 3, 3], "<i4").tobytes() + bytes(64), "not a PLOT3D xyz file"),
])
def test_zero_and_negative_dimensions(tmp_path, name, content, match):
    path = tmp_path / name
    path.write_bytes(content)
    read_error(path, match)


def test_raw_zero_dims(tmp_path):
    path = tmp_path / "v.raw"
    path.write_bytes(bytes(8))
    with pytest.raises(vio.ReadError, match="must all be positive"):
        vio.read_raw(path, (2, 0, 4), "u1")


# ---------------------------------------------------------------- NaN / Inf


def test_nan_in_raw_float_is_read_and_counted(tmp_path):
    data = np.arange(24, dtype=np.float32)
    data[[3, 10]] = np.nan
    data[17] = np.inf
    path = tmp_path / "v.raw"
    path.write_bytes(data.tobytes())
    with pytest.warns(vio.NonFiniteWarning, match=r"3 non-finite values of 24 \(2 NaN, 1 Inf; first at index \(3,\)\)"):
        vol = vio.read_raw(path, (2, 3, 4), "f4")
    assert int(np.count_nonzero(~np.isfinite(vol.data))) == 3
    with pytest.raises(vio.ReadError, match="3 non-finite values"):   # strict reading refuses them
        vio.read_raw(path, (2, 3, 4), "f4", allow_nonfinite=False)


def test_nan_in_metaimage_vti_and_plot3d_is_read_and_counted(tmp_path):
    import pyvista as pv

    from volviz.model.arrays import list_arrays

    data = np.ones((3, 3, 3), np.float64)
    data[1, 1, 1] = -np.inf
    (tmp_path / "v.raw").write_bytes(data.ravel(order="F").tobytes())
    (tmp_path / "v.mhd").write_text("NDims = 3\nDimSize = 3 3 3\nElementType = MET_DOUBLE\nElementDataFile = v.raw\n")
    with pytest.warns(vio.NonFiniteWarning, match="1 non-finite values"):
        assert list_arrays(vio.read(tmp_path / "v.mhd"))[0].nonfinite == 1
    img = pv.ImageData(dimensions=(3, 3, 3))
    img.point_data["a"] = data.ravel(order="F") * np.nan
    img.save(tmp_path / "n.vti")
    with pytest.warns(vio.NonFiniteWarning, match="point array 'a' holds 27 non-finite values"):
        assert np.isnan(vio.read(tmp_path / "n.vti").data).all()
    read_error(tmp_path / "n.vti", "point array 'a' holds 27 non-finite values", allow_nonfinite=False)
    dims = np.array([2, 2, 2], "<i4").tobytes()
    (tmp_path / "g.xyz").write_bytes(dims + np.arange(24, dtype="<f4").tobytes())
    q = np.ones(40, "<f4")
    q[5] = np.nan
    (tmp_path / "g.q").write_bytes(dims + np.zeros(4, "<f4").tobytes() + q.tobytes())
    with pytest.warns(vio.NonFiniteWarning, match=r"g.q: q solution holds 1 non-finite"):
        grid = vio.read(tmp_path / "g.xyz", q=tmp_path / "g.q")
    assert {a.name: a.nonfinite for a in list_arrays(grid)}["Density"] == 1
    q[5] = 1.0
    q[0] = -1.0  # negative density: log of a negative number in the entropy
    (tmp_path / "g.q").write_bytes(dims + np.zeros(4, "<f4").tobytes() + q.tobytes())
    with pytest.warns(vio.NonFiniteWarning, match="derived function"):
        grid = vio.read(tmp_path / "g.xyz", q=tmp_path / "g.q")
    counts = {a.name: a.nonfinite for a in list_arrays(grid)}
    assert counts["Density"] == 0 and counts["Entropy"] == 8    # every point: this q has a negative pressure


# ---------------------------------------------------------------- permissions and directories


@contextlib.contextmanager
def unprivileged():
    """Run as user 'nobody' (65534). Tests run as root here, and root reads a chmod 000 file; switching the
    effective uid makes the kernel refuse it for real. Without root the chmod alone does it."""
    if os.geteuid() != 0:
        yield
        return
    os.setegid(65534)
    os.seteuid(65534)
    try:
        yield
    finally:
        os.seteuid(0)
        os.setegid(0)


def test_unreadable_file_is_a_read_error():
    base = tempfile.mkdtemp(prefix="volviz-perm-")
    try:
        os.chmod(base, 0o755)  # traversable by everyone, so only the file's own mode matters
        path = os.path.join(base, "secret.pvm")
        with open(path, "wb") as fh:
            fh.write(b"PVM\n1 1 1\n1\n\x07")
        os.chmod(path, 0)
        with unprivileged():
            with pytest.raises(PermissionError):
                open(path, "rb").close()  # the precondition is real, not mocked
            with pytest.raises(vio.ReadError, match=r"secret.pvm: permission denied \(the file is not readable\)"):
                vio.read(path)
        os.chmod(path, stat.S_IRUSR)
        assert vio.read(path).data.ravel().tolist() == [7]  # readable again
    finally:
        shutil.rmtree(base)


def test_file_in_untraversable_directory_is_a_read_error():
    base = tempfile.mkdtemp(prefix="volviz-perm-")
    try:
        path = os.path.join(base, "inner.pgm")
        with open(path, "wb") as fh:
            fh.write(b"P5\n1 1\n255\n\x07")
        os.chmod(base, 0o700 if os.geteuid() == 0 else 0)  # root: 0700 shuts out 'nobody'
        with unprivileged():
            with pytest.raises(vio.ReadError, match="inner.pgm: permission denied"):
                vio.read(path)
        os.chmod(base, 0o700)
    finally:
        shutil.rmtree(base)


@pytest.mark.parametrize("name", ["dir.pvm", "dir.vti", "dir.vtkhdf", "dir.msh", "plain"])
def test_directory_passed_as_file(tmp_path, name):
    (tmp_path / name).mkdir()
    read_error(tmp_path / name, "is a directory, not a file")


def test_directory_and_missing_file_for_specific_readers(tmp_path):
    with pytest.raises(vio.ReadError, match="is a directory"):
        vio.read_raw(tmp_path, (1, 1, 1), "u1")
    with pytest.raises(vio.ReadError, match="is a directory"):
        vio.read_plot3d(tmp_path)
    with pytest.raises(vio.ReadError, match="no such file"):
        vio.read(tmp_path / "missing.slc")
    (tmp_path / "x.mhd").write_text("NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\nElementDataFile = gone.raw\n")
    with pytest.raises(vio.ReadError, match="gone.raw' not found"):
        vio.read(tmp_path / "x.mhd")


def test_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.pvm"
    os.mkfifo(fifo)
    read_error(fifo, "not a regular file")


def test_no_warnings_escape_for_good_files():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vio.read(data_file("storm/Storm.pvm-t01"))
        vio.read(data_file("bluntfin/bluntfinxyz.bin"))


def test_vtkhdf_dataset_claiming_too_much(tmp_path):
    import h5py

    path = tmp_path / "big.vtkhdf"
    with h5py.File(path, "w") as f:
        root = f.create_group("VTKHDF")
        root.attrs["Type"] = np.bytes_(b"ImageData")
        root.create_dataset("PointData/a", shape=(10**6, 10**6), dtype="f8")  # never written: no storage
    with allocation_budget():
        read_error(path, "dataset /VTKHDF/PointData/a claims 8000000000000 bytes")


def test_file_named_like_a_pattern_is_read_as_a_file(tmp_path):
    path = tmp_path / "scan[1].pvm"
    path.write_bytes(b"PVM\n1 1 1\n1\n\x05")
    assert vio.read(path).data.ravel().tolist() == [5]


def test_a_size_is_given_once_where_its_short_form_says_nothing_more(tmp_path):
    """``bytes_and_size``: "500 bytes", not "500 bytes (500 bytes)"; a larger count keeps its short form."""
    from volviz.io.errors import bytes_and_size

    assert bytes_and_size(500) == "500 bytes" and bytes_and_size(10000) == "10000 bytes (10 KB)"
    path = tmp_path / "short.pgm"
    path.write_bytes(b"P5\n100 100\n255\n" + bytes(500))
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    assert "needs 10000 bytes (10 KB) but the file holds only 500 bytes there" in str(info.value)
