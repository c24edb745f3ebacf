"""Damaged MAT-files v5 / v7 refused by the element walk before SciPy runs (issue #32): one line naming the file,
the variable or element and both values. Before the walk, a data size of 0 under a 6x7x5 array crashed the process
in SciPy, an unknown array class ended in UnboundLocalError and a damaged zlib stream in zlib's own words."""
from __future__ import annotations

import struct

import numpy as np
import pytest
import scipy.io

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.io.matlab import read_mat

VOLUME = np.arange(210, dtype=np.float64).reshape(6, 7, 5)


def _saved(tmp_path, compress: bool = False) -> bytearray:
    path = tmp_path / "v.mat"
    scipy.io.savemat(path, {"V": VOLUME}, do_compression=compress)
    return bytearray(path.read_bytes())


def _refusal(tmp_path, data: bytes) -> str:
    path = tmp_path / "damaged.mat"
    path.write_bytes(bytes(data))
    with pytest.raises(ReadError) as info:
        vio.read(path)  # isolated, as a user reads it
    text = str(info.value)
    assert text.startswith(str(path)) and "\n" not in text
    return text[len(str(path)):]


def _real_part_tag(data: bytearray) -> int:
    """Byte offset of the real part's tag of the single uncompressed variable V (after flags, dims, small name)."""
    pos = 128 + 8 + 16  # matrix tag, array flags
    dims = struct.unpack("<I", data[pos + 4:pos + 8])[0]
    pos += 8 + dims + (-dims % 8)
    return pos + 8  # the name "V" is a small data element


def test_an_intact_file_reads_with_its_values(tmp_path):
    path = tmp_path / "v.mat"
    path.write_bytes(bytes(_saved(tmp_path)))
    np.testing.assert_array_equal(read_mat(path).data, np.swapaxes(VOLUME, 0, 1))


def test_a_data_size_that_does_not_fit_the_dimensions(tmp_path):
    data = _saved(tmp_path)
    at = _real_part_tag(data)
    assert struct.unpack("<II", data[at:at + 8]) == (9, 1680)  # miDOUBLE, 6 * 7 * 5 * 8 bytes
    data[at + 4:at + 8] = struct.pack("<I", 0)  # crashed SciPy (segmentation fault)
    assert _refusal(tmp_path, data) == (": MAT-file variable V: its real part holds 0 bytes but 6x7x5 values of "
                                        "8 bytes need 1680")
    data[at + 4:at + 8] = struct.pack("<I", 1 << 31)
    assert "the element at byte 184 claims 2147483648 bytes but its container ends 1680 bytes after its tag" \
        in _refusal(tmp_path, data)


def test_negative_dimensions_an_unknown_class_and_a_bad_name(tmp_path):
    data = _saved(tmp_path)
    dims = bytearray(data)
    dims[164:168] = struct.pack("<i", -7)
    assert _refusal(tmp_path, dims) == (": MAT-file element at byte 128: its dimensions are [6, -7, 5]: at least "
                                        "two, none negative")
    klass = bytearray(data)
    klass[144] = 0xFF  # ended in UnboundLocalError inside SciPy
    assert _refusal(tmp_path, klass) == (": MAT-file element at byte 128: its array class is 255, which MAT-files "
                                         "do not define (1 to 17)")
    name = bytearray(data)
    name[180] = 0x01
    assert _refusal(tmp_path, name) == (": MAT-file element at byte 128: its name (1 bytes) is not a MATLAB "
                                        "variable name")


def test_a_header_of_another_byte_order_or_version(tmp_path):
    data = _saved(tmp_path)
    data[126:128] = b"XX"
    assert _refusal(tmp_path, data) == ": MAT-file header: the endian indicator is b'XX', not 'IM' or 'MI'"
    data[126:128] = b"IM"
    data[124:126] = b"\x00\x00"
    assert _refusal(tmp_path, data) == ": MAT-file header: the version is 0x0000, not 0x0100 (level 5)"


def test_a_truncated_file_and_a_damaged_compressed_variable(tmp_path):
    data = _saved(tmp_path)
    assert _refusal(tmp_path, data[:1000]) == (": MAT-file top level: the element at byte 128 claims 1736 bytes but "
                                               "its container ends 864 bytes after its tag: the file is truncated or "
                                               "damaged")
    packed = _saved(tmp_path, compress=True)
    assert struct.unpack("<I", packed[128:132])[0] == 15
    packed[-6] ^= 0x10  # inside the deflate stream's last bytes: the Adler-32 check fails
    assert _refusal(tmp_path, packed).startswith(": MAT-file element at byte 128: its zlib data is damaged (Error -3")


def test_nesting_deeper_than_the_limit(tmp_path):
    nested: object = np.ones((2, 2, 2))
    for _ in range(40):
        cell = np.empty((1, 1), dtype=object)
        cell[0, 0] = nested
        nested = cell
    path = tmp_path / "deep.mat"
    scipy.io.savemat(path, {"C": nested})
    assert _refusal(tmp_path, path.read_bytes()) == (": MAT-file variable C: cells or structs are nested deeper "
                                                     "than 32 levels")
