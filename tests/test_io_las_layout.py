"""A LAS header whose offset to the point data or VLR count does not fit the file is refused before laspy reads
(issue #32): the campaign's LAS file with that offset set to 2^31 ran until the reader's time limit (10 s in the
run, 60 s by default)."""
from __future__ import annotations

import struct

import pytest

import volviz.io as vio
from volviz.bench.robustness_made import write_made


@pytest.fixture()
def las(tmp_path):
    path = write_made(tmp_path, ["las"])["las"]
    data = bytearray(path.read_bytes())
    assert struct.unpack_from("<HII", data, 94) == (227, 227, 0)  # header size, offset to points, VLRs
    assert vio.read(path).n_points == 120
    return path, data


def _refusal(path, data) -> str:
    path.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    assert str(info.value).startswith(str(path))
    return str(info.value)[len(str(path)):]


def test_an_offset_to_the_points_beyond_the_file(las):
    path, data = las
    data[96:100] = struct.pack("<i", -2**31)
    assert _refusal(path, data) == (": its LAS header size (227) and offset to the point data (2147483648) do not fit "
                                    "a file of 4307 bytes (header size at least 227, offset between it and the end "
                                    "of the file)")


def test_more_variable_length_records_than_room_for_them(las):
    path, data = las
    data[100:104] = struct.pack("<I", 3)
    assert _refusal(path, data) == (": its LAS header counts 3 variable-length records, more than the 0 bytes between "
                                    "the header and the point data hold (54 bytes each at least)")
