"""A MINC 1 file whose dimension length disagrees with its image's size field (issue #32, the re-run's MINC bit
flip, rebuilt with ``volviz bench robustness --replay``): ``zspace`` 6 turned 7 by one bit, and nibabel read the
image's 240 bytes as 280, the next variable's bytes among them, as a 4 x 5 x 7 volume without a word. Each netCDF
variable's size field is now held against its dimensions before nibabel interprets the file."""
from __future__ import annotations

import pytest

import volviz.io as vio
from volviz.bench.robustness_formats import SEEDS


@pytest.fixture
def brain(tmp_path):
    seed = next(s for s in SEEDS if s.fmt == "minc" and s.label == "minc1-short")
    seed.write(tmp_path)
    return tmp_path / "brain.mnc"


def test_the_seed_reads_as_written(brain):
    assert vio.read(brain).data.shape == (4, 5, 6)


def test_a_dimension_length_that_disagrees_with_the_image_size_is_refused(brain):
    raw = bytearray(brain.read_bytes())
    assert raw[20:26] == b"zspace" and raw[28:32] == b"\0\0\0\x06"
    raw[31] = 7                                                   # the campaign's flip of bit 0 at byte 31
    brain.write_bytes(bytes(raw))
    with pytest.raises(vio.ReadError, match=rf"^{brain}: MINC 1: variable 'image' holds 280 bytes by its dimensions "
                                            r"\(zspace 7 x yspace 5 x xspace 4 of 2 bytes\) but its size field says "
                                            r"240: the header is damaged$"):
        vio.read(brain)
