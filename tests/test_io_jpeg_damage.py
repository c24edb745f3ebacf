"""JPEG files are decoded by VTK's libjpeg reader, which treats libjpeg's warnings as errors: a JPEG whose frame
header claims more rows than its data holds, or that is cut short, is refused (Pillow fills the missing rows with
grey and says nothing), and valid grey and colour JPEGs read with Pillow's exact pixels."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import volviz.io as vio

from conftest import data_file

CLOUDS = "sky/clouds.jpeg"


def _sof_height_at(data: bytes) -> int:
    """The byte offset of the image height in a baseline JPEG's SOF0 segment."""
    return data.index(b"\xff\xc0") + 5


def test_grey_jpeg_pixels_equal_pillows():
    path = data_file(CLOUDS)
    img = vio.read(path)
    assert img.data.shape == (512, 1024) and img.data.dtype == np.uint8
    np.testing.assert_array_equal(img.data, np.array(Image.open(path)))


def test_colour_jpeg_pixels_equal_pillows(tmp_path):
    rng = np.random.default_rng(3)
    rgb = (rng.random((48, 80, 3)) * 255).astype(np.uint8)
    path = tmp_path / "colour.jpg"
    Image.fromarray(rgb).save(path, quality=90)
    img = vio.read(path)
    assert img.data.shape == (48, 80, 3)
    np.testing.assert_array_equal(img.data, np.array(Image.open(path)))


@pytest.mark.parametrize("extra_rows", [1, 64])
def test_jpeg_taller_than_its_data_is_refused(tmp_path, extra_rows):
    data = bytearray(data_file(CLOUDS).read_bytes())
    at = _sof_height_at(bytes(data))
    height = int.from_bytes(data[at:at + 2], "big")
    assert height == 512
    data[at:at + 2] = (height + extra_rows).to_bytes(2, "big")
    path = tmp_path / "tall.jpeg"
    path.write_bytes(bytes(data))
    Image.open(path).load()  # Pillow decodes it without a word
    with pytest.raises(vio.ReadError, match=r"tall\.jpeg: VTK's vtkJPEGReader failed: libjpeg error: Corrupt JPEG "
                                            r"data: premature end of data segment"):
        vio.read(path)


def test_jpeg_cut_short_is_refused(tmp_path):
    data = data_file(CLOUDS).read_bytes()
    path = tmp_path / "cut.jpeg"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(vio.ReadError, match=r"cut\.jpeg: "):
        vio.read(path)
