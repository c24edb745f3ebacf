"""Headerless data (``volviz.io.raw_layout``): the layout guessed from the bytes of smooth volumes written in every
sample type, byte order and with a header; the shared datasets whose layout is known (headsq's 93 slices, the
HeadMRVolume .raw beside its .mhd); the MetaImage header written for a layout, slice lists and patterns read back;
and the app's dialog opening a stack of slices."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import volviz.io as vio
from conftest import data_file
from test_app_window import not_blank, viewport_image, wait_loaded, window  # noqa: F401  (the fixture)
from volviz.io.errors import ReadError
from volviz.io.raw_layout import (RawLayout, guess_layouts, headerless_data, layout_problem, layout_slice,
                                  metaimage_header, write_header)


def _smooth(shape=(48, 40, 24)) -> np.ndarray:
    """A smooth field (x fastest in the file: indexed [x, y, z], written in Fortran order) of two blobs."""
    x, y, z = np.meshgrid(*(np.linspace(-1.0, 1.0, n) for n in shape), indexing="ij")
    return np.exp(-4 * ((x - 0.3) ** 2 + y ** 2 + (z + 0.2) ** 2)) + 0.5 * np.exp(-9 * ((x + 0.4) ** 2 + (y - 0.3) ** 2
                                                                                         + z ** 2))


@pytest.mark.parametrize("dtype, order, header", [("uint8", "little", 0), ("int16", "big", 0),
                                                   ("uint16", "little", 0), ("float32", "little", 0),
                                                   ("float32", "big", 0), ("uint16", "big", 1)])
def test_a_smooth_volume_is_guessed_exactly(tmp_path, dtype, order, header):
    field = _smooth()
    if np.dtype(dtype).kind in "ui":
        info = np.iinfo(dtype)
        field = field / field.max() * (0.9 * info.max) + (0 if info.min == 0 else 0.3 * info.min)
    disk = np.dtype(dtype).newbyteorder("<" if order == "little" else ">")
    path = tmp_path / "volume.raw"
    path.write_bytes(bytes(header) + field.astype(disk).tobytes(order="F"))
    best = guess_layouts([path])[0]
    assert (best.dims, best.dtype, best.header_bytes) == ((48, 40, 24), dtype, header)
    assert best.byteorder == order or np.dtype(dtype).itemsize == 1
    assert layout_problem([path], best) is None
    np.testing.assert_array_equal(layout_slice([path], best, 5), field.astype(disk)[:, :, 5])


def test_a_stack_of_slices_and_the_shared_headerless_data():
    files = headerless_data(data_file("headsq/quarter.17"))
    assert [f.name for f in files[:3]] == ["quarter.1", "quarter.2", "quarter.3"] and len(files) == 93
    best = guess_layouts(files)[0]
    assert best.dims == (64, 64, 93) and best.dtype in ("uint16", "int16") and best.byteorder == "little"
    mr = Path(data_file("volumes/HeadMRVolume.raw"))
    assert headerless_data(mr) is None                       # its .mhd is beside it
    assert headerless_data(data_file("volumes/neghip.slc")) is None
    guessed = guess_layouts([mr])[0]
    known = vio.read(mr.with_suffix(".mhd"))
    assert guessed.dims == known.dimensions and guessed.dtype == "uint8"


def test_the_written_header_opens_the_data_and_lists_or_patterns_read_the_same(tmp_path):
    field = (_smooth((32, 24, 10)) * 1000).astype("<u2")
    files = []
    for k in range(10):
        files.append(tmp_path / f"slice.{k + 1}")
        files[-1].write_bytes(field[:, :, k].tobytes(order="F"))
    assert headerless_data(files[3]) == files
    layout = guess_layouts(files)[0]
    header = write_header(files, layout, (0.5, 0.5, 2.0), tmp_path / "unused")
    assert header == tmp_path / "slice.mhd" and "ElementDataFile = LIST\nslice.1\n" in header.read_text()
    volume = vio.read(header)
    np.testing.assert_array_equal(volume.data, field)
    assert volume.spacing == (0.5, 0.5, 2.0)
    pattern = tmp_path / "pattern.mhd"
    pattern.write_text(metaimage_header(layout, ["x"], (0.5, 0.5, 2.0)).replace("ElementDataFile = x",
                                                                                "ElementDataFile = slice.%d 1 10 1"))
    np.testing.assert_array_equal(vio.read(pattern).data, field)
    pattern.write_text(pattern.read_text().replace("1 10 1", "1 9 1"))
    with pytest.raises(ReadError, match="pattern.mhd: MetaImage ElementDataFile pattern names 9 slices, DimSize 10"):
        vio.read(pattern)


def test_layouts_that_do_not_fit_say_why(tmp_path):
    path = tmp_path / "v.raw"
    path.write_bytes(bytes(1000))
    assert layout_problem([path], RawLayout((10, 10, 10), "uint16")) == \
        "10 x 10 x 10 uint16 samples need 2000 bytes, the file holds 1000"
    assert layout_problem([path, path], RawLayout((10, 10, 3), "uint8")) == "the stack has 2 slice files, not 3"


def test_the_app_asks_the_layout_and_opens_the_stack(qtbot, window, tmp_path):  # noqa: F811
    field = (_smooth((40, 32, 16)) * 3000 - 1000).astype("<i2")      # signed: int16, not uint16
    for k in range(16):
        (tmp_path / f"ct.{k + 1:03d}").write_bytes(field[:, :, k].tobytes(order="F"))
    window.open_path(tmp_path / "ct.007")
    dialog = window.raw_dialog
    assert dialog is not None and window.error_dialog is None
    assert dialog.layout() == RawLayout((40, 32, 16), "int16", "little", 0)
    assert not dialog.preview.pixmap().isNull()
    dialog.sizes[0].setValue(41)                                   # a wrong size: said, and Open disabled
    assert "need" in dialog.problem.text() and not dialog.buttons.button(dialog.buttons.StandardButton.Open).isEnabled()
    dialog.apply_guess(0)
    dialog.spacing[2].setValue(2.5)
    dialog.buttons.button(dialog.buttons.StandardButton.Open).click()
    wait_loaded(qtbot, window)
    assert window.error_dialog is None
    assert [d.path for d in window.session.datasets] == [str(tmp_path / "ct.mhd")]
    assert vio.read(tmp_path / "ct.mhd").spacing == (1.0, 1.0, 2.5)
    assert not_blank(viewport_image(window)) > 0.02
