"""Multi-page TIFF stacks (``volviz.io.tiffstack``) through ``volviz.io.read``: ImageJ and OME-TIFF z-stacks with
their voxel sizes, channels as components, time as a series, plain page sequences, the 2D path kept for one page,
and damaged files. Every file is written here by tifffile."""
from __future__ import annotations

import numpy as np
import pytest
import tifffile

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.model import Image2D, RegularVolume, TimeSeries

PAGES = np.random.default_rng(0).integers(0, 4000, size=(4, 5, 6)).astype(np.uint16)   # (z, rows, columns)


def _as_shown(pages: np.ndarray) -> np.ndarray:
    """What the volume should hold: x along the columns, y up the image (the top row at the largest y), z the
    page."""
    return np.transpose(pages, (2, 1, 0) + tuple(range(3, pages.ndim)))[:, ::-1]


def test_an_imagej_z_stack_is_a_volume_with_its_voxel_size(tmp_path):
    path = tmp_path / "cells.tif"
    tifffile.imwrite(path, PAGES, imagej=True, resolution=(1 / 0.2, 1 / 0.2),
                     metadata={"spacing": 0.8, "unit": "um", "axes": "ZYX"})
    volume = vio.read(path)
    assert isinstance(volume, RegularVolume) and volume.dimensions == (6, 5, 4)
    assert volume.spacing == pytest.approx((0.2, 0.2, 0.8))
    np.testing.assert_array_equal(volume.data, _as_shown(PAGES))
    assert volume.data[0, 4, 0] == PAGES[0, 0, 0]      # the first page's top-left pixel: x 0, top y, z 0


def test_an_ome_tiff_takes_its_physical_sizes(tmp_path):
    path = tmp_path / "cells.ome.tif"
    tifffile.imwrite(path, PAGES, ome=True, metadata={"axes": "ZYX", "PhysicalSizeX": 0.5, "PhysicalSizeY": 0.25,
                                                      "PhysicalSizeZ": 3.0})
    volume = vio.read(path)
    assert volume.spacing == pytest.approx((0.5, 0.25, 3.0))
    np.testing.assert_array_equal(volume.data, _as_shown(PAGES))


def test_channels_are_components_and_time_is_a_series(tmp_path):
    channels = np.stack([PAGES, PAGES // 2], axis=1)                      # (z, c, rows, columns)
    tifffile.imwrite(tmp_path / "c.tif", channels, imagej=True, metadata={"axes": "ZCYX"})
    volume = vio.read(tmp_path / "c.tif")
    assert list(volume.arrays) == ["intensity"] and volume.arrays["intensity"].shape == (6, 5, 4, 2)
    np.testing.assert_array_equal(volume.arrays["intensity"], _as_shown(np.moveaxis(channels, 1, 3)))

    steps = np.stack([PAGES, PAGES + 1, PAGES + 2])                        # (t, z, rows, columns)
    tifffile.imwrite(tmp_path / "t.tif", steps, imagej=True, metadata={"axes": "TZYX", "finterval": 2.5})
    series = vio.read(tmp_path / "t.tif")
    assert isinstance(series, TimeSeries) and list(series.times) == [0.0, 2.5, 5.0]
    np.testing.assert_array_equal(series.frame(2).data, _as_shown(PAGES + 2))


def test_plain_pages_are_a_stack_and_one_page_stays_an_image(tmp_path):
    with tifffile.TiffWriter(tmp_path / "pages.tif") as writer:
        for page in PAGES:
            writer.write(page, metadata=None, contiguous=False)
    volume = vio.read(tmp_path / "pages.tif")
    assert volume.spacing == (1.0, 1.0, 1.0)
    np.testing.assert_array_equal(volume.data, _as_shown(PAGES))
    tifffile.imwrite(tmp_path / "one.tif", PAGES[0])
    image = vio.read(tmp_path / "one.tif")
    assert isinstance(image, Image2D)
    np.testing.assert_array_equal(image.data, PAGES[0])


def test_damaged_stacks_are_refused(tmp_path):
    path = tmp_path / "cells.tif"
    tifffile.imwrite(path, PAGES, imagej=True, metadata={"axes": "ZYX"})
    data = path.read_bytes()
    (tmp_path / "cut.tif").write_bytes(data[: len(data) // 2])
    with pytest.raises(ReadError, match="cut.tif"):
        vio.read(tmp_path / "cut.tif")
    big = np.zeros((2, 2, 2, 2, 3, 4), np.uint8)
    tifffile.imwrite(tmp_path / "axes.tif", big, metadata={"axes": "ZQRCYX"})
    with pytest.raises(ReadError, match=r"axes.tif: a TIFF stack with axes .*volviz reads one depth axis"):
        vio.read(tmp_path / "axes.tif")


def test_a_tiff_stack_renders_legibly_on_first_open(tmp_path):
    from volviz.render.export import render_session
    from volviz.scene.opening import data_session

    z, y, x = np.mgrid[-1:1:16j, -1:1:32j, -1:1:32j]
    cells = ((np.sqrt(x * x + y * y + z * z) < 0.7) * 3000 + 100).astype(np.uint16)
    path = tmp_path / "cells.tif"
    tifffile.imwrite(path, cells, imagej=True, metadata={"spacing": 2.0, "axes": "ZYX"})
    img = np.asarray(render_session(data_session(path), None, (160, 120)))
    changed = np.abs(img[..., :3].astype(int) - img[0, 0, :3].astype(int)).max(axis=-1) > 24
    assert 0.1 < changed.mean() < 0.9
