"""Synthetic files in every layout the readers promise (PVM v1-3 8/16 bit, PGM/PPM ASCII/binary 8/16 bit,
SLC raw and run-length coded, MetaImage .mhd/.mha/compressed/2D, raw, PLOT3D layouts checked against VTK, VTK XML
grids, meshio, series), written here and read back exactly."""
from __future__ import annotations

import zlib

import meshio
import numpy as np
import pytest
import pyvista as pv
import vtk
from vtkmodules.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from volviz.model import CurvilinearGrid, Image2D, RegularVolume, TimeSeries, UnstructuredMesh

RNG = np.random.default_rng(7)


def volume_u8(shape=(5, 4, 3)) -> np.ndarray:
    return RNG.integers(0, 256, size=shape, dtype=np.uint8)


# ---------------------------------------------------------------- PVM


def pvm_bytes(data: np.ndarray, version: int = 1, spacing=(1.0, 1.0, 1.0), trailer: bytes = b"") -> bytes:
    nx, ny, nz = data.shape
    bpv = data.dtype.itemsize
    magic = {1: b"PVM\n", 2: b"PVM2\n", 3: b"PVM3\n"}[version]
    head = magic + f"{nx} {ny} {nz}\n".encode()
    if version > 1:
        head += ("%g %g %g\n" % tuple(spacing)).encode()
    head += f"{bpv}\n".encode()
    body = data.astype(">u2" if bpv == 2 else np.uint8).ravel(order="F").tobytes()
    return head + body + trailer


@pytest.mark.parametrize("version", [1, 2, 3])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_pvm_versions_and_depths(tmp_path, version, dtype):
    data = RNG.integers(0, np.iinfo(dtype).max, size=(6, 5, 4)).astype(dtype)
    path = tmp_path / "v.pvm"
    trailer = b"description\0courtesy\0parameter\0comment\0" if version == 3 else b""
    path.write_bytes(pvm_bytes(data, version, (0.5, 2.0, 1.25), trailer))
    vol = vio.read(path)
    assert isinstance(vol, RegularVolume) and vol.data.dtype == dtype and vol.data.dtype.isnative
    np.testing.assert_array_equal(vol.data, data)
    assert vol.spacing == ((1.0, 1.0, 1.0) if version == 1 else (0.5, 2.0, 1.25))


def test_pvm_16bit_is_big_endian(tmp_path):
    path = tmp_path / "b.pvm"
    path.write_bytes(b"PVM\n1 1 2\n2\n\x01\x02\xff\x00")
    vol = vio.read(path)
    assert vol.data.ravel().tolist() == [0x0102, 0xFF00]


@pytest.mark.parametrize("magic", [b"DDS v3d\n", b"DDS v3e\n"])
def test_pvm_dds_compressed_is_recognised_and_refused(tmp_path, magic):
    path = tmp_path / "c.pvm"
    path.write_bytes(magic + bytes(100))
    with pytest.raises(vio.ReadError, match="DDS-compressed PVM") as err:
        vio.read(path)
    assert str(path) in str(err.value)


# ---------------------------------------------------------------- PGM / PPM


def pnm_bytes(img: np.ndarray, maxval: int, ascii_: bool = False, comment: bool = True) -> bytes:
    colour = img.ndim == 3
    magic = {(False, True): b"P2", (True, True): b"P3", (False, False): b"P5", (True, False): b"P6"}[(colour, ascii_)]
    head = magic + (b"\n# made by volviz tests\n" if comment else b"\n")
    head += f"{img.shape[1]} {img.shape[0]}\n{maxval}\n".encode()
    if ascii_:
        return head + " ".join(str(int(v)) for v in img.ravel()).encode() + b"\n"
    return head + img.astype(">u2" if maxval > 255 else np.uint8).tobytes()


@pytest.mark.parametrize("colour", [False, True])
@pytest.mark.parametrize("maxval", [255, 1023, 65535])
@pytest.mark.parametrize("ascii_", [False, True])
def test_pnm_variants(tmp_path, colour, maxval, ascii_):
    shape = (4, 7, 3) if colour else (4, 7)
    img = RNG.integers(0, maxval + 1, size=shape)
    path = tmp_path / ("x.ppm" if colour else "x.pgm")
    path.write_bytes(pnm_bytes(img, maxval, ascii_))
    out = vio.read(path)
    assert isinstance(out, Image2D) and out.maxval == maxval
    assert out.data.dtype == (np.uint8 if maxval < 256 else np.uint16)
    np.testing.assert_array_equal(out.data, img)


def test_pnm_16bit_matches_pillow(tmp_path):
    """vtkPNMReader reads only 8-bit samples, so 16-bit PGM is checked against Pillow instead."""
    from PIL import Image

    img = RNG.integers(0, 65536, size=(5, 6))
    path = tmp_path / "w.pgm"
    path.write_bytes(pnm_bytes(img, 65535))
    with Image.open(path) as im:
        theirs = np.array(im)
    np.testing.assert_array_equal(vio.read(path).data, theirs)


# ---------------------------------------------------------------- SLC


def rle_encode(plane: bytes) -> bytes:
    """A simple SLC run-length coder: runs of equal bytes (<=127) and literal stretches (<=127), then 0."""
    out, i, n = bytearray(), 0, len(plane)
    while i < n:
        j = i
        while j < n and plane[j] == plane[i] and j - i < 127:
            j += 1
        if j - i >= 3:
            out += bytes([j - i, plane[i]])
            i = j
            continue
        j = i
        while j < n and j - i < 127 and not (j + 2 < n and plane[j] == plane[j + 1] == plane[j + 2]):
            j += 1
        out += bytes([0x80 | (j - i)]) + plane[i:j]
        i = j
    return bytes(out) + b"\0"


def slc_bytes(data: np.ndarray, compression: int, spacing=(1.0, 1.0, 1.0), icon=(2, 3)) -> bytes:
    nx, ny, nz = data.shape
    head = f"11111\n{nx} {ny} {nz} 8\n{spacing[0]:f} {spacing[1]:f} {spacing[2]:f}\n1 6 0 {compression}\n"
    head += f"{icon[0]} {icon[1]} X"
    out = bytearray(head.encode()) + bytes(3 * icon[0] * icon[1])
    for z in range(nz):
        plane = data[:, :, z].ravel(order="F").tobytes()
        if compression == 0:
            out += plane
        else:
            code = rle_encode(plane)
            out += f"{len(code)} X".encode() + code
    return bytes(out)


@pytest.mark.parametrize("compression", [0, 1])
def test_slc_raw_and_rle_match_vtk(tmp_path, compression):
    data = np.zeros((9, 7, 4), dtype=np.uint8)
    data[2:7, 1:5, 1:3] = RNG.integers(0, 256, size=(5, 4, 2))
    data[:, :, 3] = 200
    path = tmp_path / "v.slc"
    path.write_bytes(slc_bytes(data, compression, (0.5, 0.75, 2.0)))
    vol = vio.read(path)
    np.testing.assert_array_equal(vol.data, data)
    assert vol.spacing == (0.5, 0.75, 2.0)
    r = vtk.vtkSLCReader()
    r.SetFileName(str(path))
    r.Update()
    np.testing.assert_array_equal(vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()), data.ravel(order="F"))


# ---------------------------------------------------------------- MetaImage and raw


def mhd_text(dims, etype, extra="", datafile="v.raw") -> str:
    return (f"ObjectType = Image\nNDims = {len(dims)}\nDimSize = {' '.join(map(str, dims))}\n"
            f"ElementSpacing = {' '.join(['0.5'] * len(dims))}\nOffset = {' '.join(['1'] * len(dims))}\n"
            f"ElementType = {etype}\n{extra}ElementDataFile = {datafile}\n")


@pytest.mark.parametrize("etype,dtype", [("MET_UCHAR", "u1"), ("MET_SHORT", "i2"), ("MET_FLOAT", "f4"),
                                         ("MET_DOUBLE", "f8"), ("MET_USHORT", "u2")])
@pytest.mark.parametrize("msb", [False, True])
def test_metaimage_types_and_byte_orders_match_vtk(tmp_path, etype, dtype, msb):
    data = (RNG.random((4, 3, 5)) * 100).astype(dtype)
    (tmp_path / "v.raw").write_bytes(data.astype(np.dtype(dtype).newbyteorder(">" if msb else "<"))
                                     .ravel(order="F").tobytes())
    path = tmp_path / "v.mhd"
    path.write_text(mhd_text((4, 3, 5), etype, f"ElementByteOrderMSB = {msb}\n"))
    vol = vio.read(path)
    np.testing.assert_array_equal(vol.data, data)
    assert vol.spacing == (0.5, 0.5, 0.5) and vol.origin == (1.0, 1.0, 1.0)
    r = vtk.vtkMetaImageReader()
    r.SetFileName(str(path))
    r.Update()
    np.testing.assert_array_equal(vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()), vol.data.ravel(order="F"))


def test_metaimage_mha_local_compressed_and_2d(tmp_path):
    data = RNG.integers(0, 1000, size=(6, 5, 4)).astype(np.uint16)
    packed = zlib.compress(data.astype("<u2").ravel(order="F").tobytes())
    path = tmp_path / "v.mha"
    path.write_bytes(mhd_text((6, 5, 4), "MET_USHORT", f"CompressedData = True\nCompressedDataSize = {len(packed)}\n",
                              "LOCAL").encode() + packed)
    np.testing.assert_array_equal(vio.read(path).data, data)
    img = RNG.integers(0, 255, size=(3, 8)).astype(np.uint8)  # rows = DimSize[1]
    path2 = tmp_path / "i.mha"
    path2.write_bytes(mhd_text((8, 3), "MET_UCHAR", "", "LOCAL").encode() + img.tobytes())
    out = vio.read(path2)
    assert isinstance(out, Image2D)
    np.testing.assert_array_equal(out.data, img)


@pytest.mark.parametrize("byteorder", ["little", "big"])
def test_read_raw_float_with_header(tmp_path, byteorder):
    data = RNG.random((3, 4, 5)).astype(np.float32)
    path = tmp_path / "v.raw"
    bo = "<" if byteorder == "little" else ">"
    path.write_bytes(b"HEADER!!" + data.astype(bo + "f4").ravel(order="F").tobytes())
    vol = vio.read_raw(path, (3, 4, 5), "float32", byteorder, header_bytes=8, spacing=(1, 2, 3))
    np.testing.assert_array_equal(vol.data, data)
    assert vol.data.dtype == np.float32 and vol.data.dtype.isnative and vol.spacing == (1.0, 2.0, 3.0)
    same = vio.read(path, dims=(3, 4, 5), dtype="f4", byteorder=byteorder, header_bytes=8)
    np.testing.assert_array_equal(same.data, data)


# ---------------------------------------------------------------- PLOT3D layouts against VTK


def plot3d_files(tmp_path, bo="<", markers=False, multigrid=False, precision=4, iblank=False, dims=(4, 3, 5)):
    n = int(np.prod(dims))
    ii, jj, kk = np.meshgrid(*[np.arange(d, dtype=float) for d in dims], indexing="ij")
    xyz = np.stack([ii + 0.1 * jj, jj * 1.5, kk + 0.05 * ii * kk], axis=-1)
    q = np.empty(dims + (5,))
    q[..., 0] = 1.0 + 0.1 * ii + 0.01 * kk
    q[..., 1:4] = 0.2 * xyz
    q[..., 4] = 3.0 + 0.5 * jj
    real, intt = f"{bo}f{precision}", f"{bo}i4"

    def rec(payload: bytes) -> bytes:
        m = np.array([len(payload)], dtype=intt).tobytes()
        return m + payload + m if markers else payload

    head = (rec(np.array([1], intt).tobytes()) if multigrid else b"") + rec(np.array(dims, intt).tobytes())
    body = np.concatenate([xyz[..., c].ravel(order="F") for c in range(3)]).astype(real).tobytes()
    ib = np.where((ii + jj) % 3 == 0, 0, 1)
    if iblank:
        body += ib.ravel(order="F").astype(intt).tobytes()
    (tmp_path / "g.xyz").write_bytes(head + rec(body))
    cond = np.array([0.8, 2.0, 1e5, 0.5]).astype(real).tobytes()
    qbody = np.concatenate([q[..., c].ravel(order="F") for c in range(5)]).astype(real).tobytes()
    (tmp_path / "g.q").write_bytes(head + rec(cond) + rec(qbody))
    return xyz, q, ib


@pytest.mark.parametrize("bo,markers,multigrid,precision,iblank", [
    ("<", False, False, 4, False), (">", True, False, 4, False), ("<", True, True, 8, False),
    ("<", False, True, 4, True), (">", True, True, 8, True),
])
def test_plot3d_layouts_detected_and_match_vtk(tmp_path, bo, markers, multigrid, precision, iblank):
    xyz, q, ib = plot3d_files(tmp_path, bo, markers, multigrid, precision, iblank)
    grid = vio.read(tmp_path / "g.xyz", q=tmp_path / "g.q")
    assert isinstance(grid, CurvilinearGrid) and grid.dimensions == (4, 3, 5)
    np.testing.assert_allclose(grid.points, xyz, rtol=1e-6)
    np.testing.assert_allclose(grid.point_data["Density"], q[..., 0], rtol=1e-6)
    if iblank:
        np.testing.assert_array_equal(grid.point_data["IBlank"], ib)
    r = vtk.vtkMultiBlockPLOT3DReader()
    r.SetXYZFileName(str(tmp_path / "g.xyz"))
    r.SetQFileName(str(tmp_path / "g.q"))
    r.SetByteOrder(0 if bo == ">" else 1)
    r.SetHasByteCount(markers)
    r.SetMultiGrid(multigrid)
    r.SetDoublePrecision(precision == 8)
    r.SetIBlanking(iblank)
    r.SetBinaryFile(1)
    for fn in (110, 120, 153, 170):
        r.AddFunction(fn)
    r.Update()
    pd = r.GetOutput().GetBlock(0).GetPointData()
    for name in ("Density", "StagnationEnergy", "Pressure", "Temperature", "VelocityMagnitude", "Entropy"):
        theirs = vtk_to_numpy(pd.GetArray(name)).astype(np.float64)
        np.testing.assert_allclose(grid.point_data[name].ravel(order="F"), theirs, rtol=3e-6, atol=1e-6,
                                   err_msg=name)


def test_plot3d_grid_without_q_and_explicit_block(tmp_path):
    xyz, _, _ = plot3d_files(tmp_path, multigrid=True)
    grid = vio.read_plot3d(tmp_path / "g.xyz", block=0)
    assert grid.point_data == {} and grid.active is None
    with pytest.raises(vio.ReadError, match="block 3 requested"):
        vio.read_plot3d(tmp_path / "g.xyz", block=3)


# ---------------------------------------------------------------- VTK XML, meshio, series


def test_vtk_xml_grids_to_model_types(tmp_path):
    ug = pv.ImageData(dimensions=(3, 4, 2)).cast_to_unstructured_grid()
    ug = ug.triangulate().merge(pv.ImageData(dimensions=(2, 2, 2), origin=(5, 5, 5)).cast_to_unstructured_grid())
    ug.point_data["s"] = np.arange(ug.n_points, dtype=float)
    ug.cell_data["id"] = np.arange(ug.n_cells)
    ug.save(tmp_path / "u.vtu")
    mesh = vio.read(tmp_path / "u.vtu")
    assert isinstance(mesh, UnstructuredMesh)
    # the voxel (VTK type 11) reads as the hexahedron (12) it is (tests/test_io_axis_aligned_cells.py)
    assert {t for t, _ in mesh.cells} == {10, 12} and mesh.n_cells == ug.n_cells
    back = mesh.to_pyvista()
    # cell data follows its cells through the regrouping by type
    for c in (0, ug.n_cells - 1):
        orig = ug.get_cell(int(c)).point_ids
        k = int(np.flatnonzero(back.cell_data["id"] == c)[0])
        assert sorted(back.get_cell(k).point_ids) == sorted(orig)
    sg = pv.ImageData(dimensions=(3, 4, 5), spacing=(1, 2, 3)).cast_to_structured_grid()
    sg.point_data["v"] = np.arange(60, dtype=np.float32)
    sg.save(tmp_path / "s.vts")
    cg = vio.read(tmp_path / "s.vts")
    assert isinstance(cg, CurvilinearGrid) and cg.dimensions == (3, 4, 5)
    np.testing.assert_array_equal(cg.points[2, 3, 4], [2.0, 6.0, 12.0])
    np.testing.assert_array_equal(cg.point_data["v"].ravel(order="F"), np.arange(60))
    rg = pv.RectilinearGrid(np.array([0.0, 1.0, 3.0]), np.array([0.0, 2.0]), np.array([0.0, 1.0, 5.0, 6.0]))
    rg.point_data["w"] = np.arange(24.0)
    rg.save(tmp_path / "r.vtr")
    cr = vio.read(tmp_path / "r.vtr")
    assert cr.dimensions == (3, 2, 4)
    np.testing.assert_array_equal(cr.points[2, 1, 2], [3.0, 2.0, 5.0])


def test_meshio_formats_to_unstructured_mesh(tmp_path):
    pts = RNG.random((6, 3))
    tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
    tris = np.array([[0, 1, 5]])
    path = tmp_path / "m.xdmf"
    meshio.write(path, meshio.Mesh(pts, [("tetra", tets), ("triangle", tris)], point_data={"t": np.arange(6.0)}))
    mesh = vio.read(path)
    assert isinstance(mesh, UnstructuredMesh)
    blocks = dict(mesh.cells)
    np.testing.assert_array_equal(blocks[10], tets)
    np.testing.assert_array_equal(blocks[5], tris)
    np.testing.assert_allclose(mesh.points, pts)
    np.testing.assert_array_equal(mesh.point_data["t"], np.arange(6.0))
    inp = tmp_path / "m.inp"
    meshio.write(inp, meshio.Mesh(pts, [("tetra", tets), ("triangle", tris)]))
    assert vio.read(inp).n_cells == 3


def test_read_series_printf_pattern_and_frame_consistency(tmp_path):
    for k in (1, 2, 10):
        (tmp_path / f"s{k:02d}.pvm").write_bytes(pvm_bytes(np.full((2, 2, 2), k, np.uint8)))
    series = vio.read(str(tmp_path / "s%02d.pvm"))
    assert isinstance(series, TimeSeries) and series.times.tolist() == [1.0, 2.0, 10.0]
    assert int(series.frame(2).data[0, 0, 0]) == 10
    (tmp_path / "s02.pvm").write_bytes(pvm_bytes(np.zeros((3, 2, 2), np.uint8)))
    fresh = vio.read_series(str(tmp_path / "s*.pvm"))
    with pytest.raises(vio.ReadError, match="frame 1"):
        fresh.frame(1)
    with pytest.raises(vio.ReadError, match="no files match"):
        vio.read_series(str(tmp_path / "nothing*.pvm"))


def test_supported_formats_lists_every_reader():
    names = " ".join(d for d, _ in vio.supported_formats())
    for word in ("PLOT3D", "PVM", "SLC", "MetaImage", "VTK legacy", "VTK XML", "VTKHDF", "PGM/PPM", "DEM", "meshio"):
        assert word in names
    globs = {g for _, gs in vio.supported_formats() for g in gs}
    assert {"*.pvm", "*.mhd", "*.vti", "*.msh", "*.dem"} <= globs
    assert vio.open_dialog_filter().startswith("All supported (")
