"""zlib-compressed MetaImage (.mhd + .zraw) whose CompressedDataSize is stale: the inflated size is what must agree
with the dimensions (the whole stream; VTK's vtkMetaImageReader, which inflates only the bytes the field names,
agrees where the field is right, and gives a garbled tail or nothing where it is stale); the stale field is a
ReadWarning, and a stream that really falls short is still refused."""
from __future__ import annotations

import warnings
import zlib

import numpy as np
import pytest
from vtk.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from volviz.io.errors import ReadError, ReadWarning

DATA = np.random.default_rng(3).integers(0, 4000, size=(7, 6, 5)).astype(np.int16)   # (x, y, z)


def _write(tmp_path, declared_delta: int | None, packed: bytes | None = None):
    packed = zlib.compress(DATA.astype("<i2").ravel(order="F").tobytes(), 6) if packed is None else packed
    size = "" if declared_delta is None else f"CompressedDataSize = {len(packed) + declared_delta}\n"
    (tmp_path / "ct.zraw").write_bytes(packed)
    (tmp_path / "ct.mhd").write_text("ObjectType = Image\nNDims = 3\nDimSize = 7 6 5\nElementType = MET_SHORT\n"
                                     "ElementSpacing = 0.5 0.5 2\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                                     f"CompressedData = True\n{size}ElementDataFile = ct.zraw\n")
    return tmp_path / "ct.mhd", len(packed)


def _vtk(path):
    import vtk

    reader = vtk.vtkMetaImageReader()
    reader.SetFileName(str(path))
    reader.Update()
    image = reader.GetOutput()
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(image.GetDimensions()[::-1]).transpose(2, 1, 0)


@pytest.mark.parametrize("delta", [-40, +25])
def test_a_stale_compressed_size_is_a_warning_when_the_stream_inflates_in_full(tmp_path, delta):
    path, length = _write(tmp_path, delta)
    with pytest.warns(ReadWarning, match=rf"ct.zraw: the header's CompressedDataSize \({length + delta}\) is not the "
                                         rf"length of its zlib stream \({length} bytes\), which inflates to exactly "
                                         r"the 420 bytes"):
        volume = vio.read(path)
    np.testing.assert_array_equal(volume.data, DATA)
    assert volume.spacing == (0.5, 0.5, 2.0)


def test_a_right_or_missing_compressed_size_says_nothing(tmp_path):
    for delta in (0, None):
        path, _ = _write(tmp_path, delta)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            np.testing.assert_array_equal(vio.read(path, isolate=False).data, DATA)
        np.testing.assert_array_equal(_vtk(path), DATA)


def test_a_stream_that_falls_short_is_refused(tmp_path):
    packed = zlib.compress(DATA.astype("<i2").ravel(order="F").tobytes(), 6)
    path, _ = _write(tmp_path, 0, packed[: len(packed) // 2])
    with pytest.raises(ReadError, match=r"ct.zraw: MetaImage 7x6x5 MET_SHORT compressed data inflates to \d+ bytes, "
                                        r"the header needs 420"):
        vio.read(path)
    path, _ = _write(tmp_path, 100, packed[: len(packed) // 2])
    with pytest.raises(ReadError, match=r"ct.zraw: MetaImage CompressedDataSize needs \d+ bytes .* truncated"):
        vio.read(path)
