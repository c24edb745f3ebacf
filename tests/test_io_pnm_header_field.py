"""A PGM/PPM header field that runs into the raster (issue #32): the seed-33 campaign's slowest refusals were
``sky/SkyDome.ppm`` (2048 x 512 RGB, 3 MB) with its width or height emptied or a bit of its header flipped, so that
the maxval token ran on into a raster holding no whitespace byte; the header was read again in doubling pieces up to
the whole file (1.0-1.3 s median on the loaded machine) before "PNM header is not followed by a whitespace byte and
the raster". A header field is a decimal number, so one longer than 32 bytes is refused at once, naming the field."""
from __future__ import annotations

import numpy as np
import pytest

import volviz.io as vio
from conftest import data_file


def _ppm(path, header: bytes, rows: int = 512, cols: int = 2048) -> None:
    """A PPM of one sky colour, no byte of it whitespace (like SkyDome.ppm's raster)."""
    path.write_bytes(header + np.full((rows, cols, 3), (216, 233, 250), np.uint8).tobytes())


@pytest.mark.parametrize("header, field", [(b"P6\n 512\n255\n", "maxval"), (b"P6\n2048 \n255\n", "maxval"),
                                           (b"P6 2048 512 ", "maxval"), (b"P6\n2048", "width")])
def test_a_header_field_run_into_the_raster_is_refused_naming_it(tmp_path, header, field):
    path = tmp_path / "sky.ppm"
    _ppm(path, header)
    with pytest.raises(vio.ReadError, match=rf"^{path}: PNM {field} runs on for more than 32 bytes without a "
                                            r"whitespace byte: the header is damaged$"):
        vio.read(path)


def test_the_campaigns_case_and_the_intact_file(tmp_path):
    """SkyDome.ppm's width emptied (the campaign's case 3329 at seed 33) is refused so; the file itself reads, and
    so does a header with a comment longer than the field limit."""
    sky = data_file("sky/SkyDome.ppm").read_bytes()
    assert sky.startswith(b"P6\n2048 512\n255\n")
    path = tmp_path / "SkyDome.ppm"
    path.write_bytes(sky.replace(b"2048", b"", 1))
    with pytest.raises(vio.ReadError, match=r"PNM maxval runs on for more than 32 bytes"):
        vio.read(path)
    path.write_bytes(b"P6\n# " + b"a comment of many words " * 300 + b"\n" + sky[3:])
    image = vio.read(path)
    assert image.data.shape == (512, 2048, 3)
    assert image.data.tobytes() == sky[len(b"P6\n2048 512\n255\n"):]
