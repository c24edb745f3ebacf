"""The .vvz container: per-brick CRC32, corrupt-brick isolation, truncation / magic errors, header fuzzing."""
from __future__ import annotations

import struct
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from volviz.io import ReadError
from volviz.model.datasets import RegularVolume
from volviz.regular.codec import compress, decompress, info
from volviz.regular.container import (HEADER_SIZE, KIND_NODE, CorruptBrickError, CorruptBrickWarning, Reader,
                                      VVZError, parse_header)


def _smooth_volume(shape=(64, 40, 70)) -> np.ndarray:
    x, y, z = np.meshgrid(*[np.linspace(0, 3, n) for n in shape], indexing="ij")
    rng = np.random.default_rng(5)
    return (120 + 60 * np.sin(x * 2) * np.cos(y * 3) + 40 * np.sin(z * 4) + rng.integers(0, 6, shape)).astype(np.uint8)


@pytest.fixture
def packed(tmp_path):
    data = _smooth_volume()
    path = tmp_path / "v.vvz"
    compress(RegularVolume(data), path)
    return data, path


def test_container_roundtrip_and_info(packed):
    data, path = packed
    meta = info(path)
    assert meta["dims"] == [64, 40, 70] and meta["dtype"] == "uint8" and meta["levels"] == 3
    assert meta["bricks"] == 12 + 2 + 1 + 1  # tiles of levels 1, 2, 3 + the root
    assert meta["ratio"] == pytest.approx(data.size / path.stat().st_size)
    assert not list(path.parent.glob("*.tmp"))  # atomic write left no temporary file


def test_corrupt_brick_is_named_and_the_rest_loads(packed):
    data, path = packed
    rd = Reader(path)
    table = rd.table.copy()
    rd.close()
    # the level-1 brick of tile 5 (tile grid 2 x 2 x 3: t = 1, 0, 1 -> voxels x 32..64, y 0..32, z 32..64)
    i = int(np.nonzero((table["level"] == 1) & (table["kind"] == KIND_NODE) & (table["tile"] == 5))[0][0])
    raw = bytearray(path.read_bytes())
    raw[int(table[i]["offset"]) + int(table[i]["size"]) // 2] ^= 0x5A
    path.write_bytes(bytes(raw))
    report: list = []
    with pytest.warns(CorruptBrickWarning, match=rf"brick {i} \(node, level 1, tile 5"):
        back = decompress(path, report=report).data
    assert len(report) == 1 and report[0]["region"] == [[32, 64], [0, 32], [32, 64]]
    mask = np.zeros(data.shape, bool)
    mask[32:64, 0:32, 32:64] = True
    assert np.array_equal(back[~mask], data[~mask])  # everything else is still bit-exact
    # the damaged region is filled from the coarser level: close to the data, not zeros
    err = np.abs(back[mask].astype(int) - data[mask]).mean()
    assert 0 < err < 8
    with pytest.raises(CorruptBrickError, match="tile 5"):
        decompress(path, strict=True)


def test_corrupt_root_still_loads(packed):
    data, path = packed
    rd = Reader(path)
    root = rd.table[rd.table["kind"] == 0][0]
    rd.close()
    raw = bytearray(path.read_bytes())
    raw[int(root["offset"])] ^= 0xFF
    path.write_bytes(bytes(raw))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        back = decompress(path).data
    assert any("root" in str(w.message) for w in caught)
    assert back.shape == data.shape


def test_truncated_and_wrong_magic(packed, tmp_path):
    _, path = packed
    raw = path.read_bytes()
    short = tmp_path / "short.vvz"
    short.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(VVZError, match="truncated"):
        decompress(short)
    tiny = tmp_path / "tiny.vvz"
    tiny.write_bytes(raw[:10])
    with pytest.raises(VVZError, match="truncated"):
        info(tiny)
    bad = tmp_path / "bad.vvz"
    bad.write_bytes(b"PVM\n" + raw[4:])
    with pytest.raises(VVZError, match="not a .vvz"):
        decompress(bad)
    assert issubclass(VVZError, ReadError)


def test_damaged_table_and_header(packed, tmp_path):
    _, path = packed
    raw = bytearray(path.read_bytes())
    raw[-5] ^= 1
    p = tmp_path / "t.vvz"
    p.write_bytes(bytes(raw))
    with pytest.raises(VVZError, match="table checksum"):
        decompress(p)
    raw = bytearray(path.read_bytes())
    raw[20] ^= 1
    p.write_bytes(bytes(raw))
    with pytest.raises(VVZError, match="header checksum|outside the file"):
        decompress(p)


@settings(max_examples=300, deadline=None)
@given(head=st.binary(min_size=0, max_size=80), size=st.integers(min_value=0, max_value=1 << 40))
def test_parse_header_fuzz_random(head, size):
    try:
        h = parse_header(head, size)
    except VVZError:
        return
    assert h["meta_off"] + h["meta_len"] <= size and h["table_off"] + 32 * h["table_count"] <= size


@settings(max_examples=300, deadline=None)
@given(pos=st.integers(min_value=8, max_value=59), value=st.integers(min_value=0, max_value=255),
       size=st.integers(min_value=HEADER_SIZE, max_value=1 << 20))
def test_parse_header_fuzz_mutated(tmp_path_factory, pos, value, size):
    from volviz.regular.container import MAGIC, VERSION, _HDR, crc32
    head = _HDR.pack(MAGIC, VERSION, HEADER_SIZE, 0, 64, 100, 164, 3, 0, 0, 0)
    head = bytearray(head + struct.pack("<I", crc32(head)))
    head[pos] = value
    head[60:64] = struct.pack("<I", crc32(bytes(head[:60])))  # a consistent checksum: the fields must be checked
    try:
        h = parse_header(bytes(head), size)
    except VVZError:
        return
    assert h["meta_len"] <= 16 << 20
    assert h["meta_off"] + h["meta_len"] <= size and h["table_off"] + 32 * h["table_count"] <= size


@pytest.mark.parametrize("old_version", [None, 2])
def test_older_arith_coder_version_is_refused(tmp_path, old_version):
    # arith coder version 2 changed the contexts, version 3 added the S-transform model: older streams must not be
    # decoded with them
    src, old = tmp_path / "a.vvz", tmp_path / "old.vvz"
    compress(RegularVolume(_smooth_volume((40, 20, 20))), src, coder="arith")
    rd = Reader(src)
    from volviz.regular.container import Writer
    with Writer(old) as w:
        for rec in rd.table:
            off, size = int(rec["offset"]), int(rec["size"])
            w.add(int(rec["level"]), int(rec["kind"]), int(rec["tile"]), np.asarray(rd.payload[off:off + size]),
                  int(rec["transform"]))
        meta = dict(rd.meta)
        assert meta["coder_version"] == 3
        if old_version is None:
            meta.pop("coder_version")  # files written before the field existed
        else:
            meta["coder_version"] = old_version
        w.close(meta)
    rd.close()
    with pytest.raises(VVZError, match=rf"old\.vvz.*arith coder version {old_version or 1} is not supported"):
        decompress(old)


def test_container_version_1_is_refused(tmp_path):
    # version 2 added the per-brick transform field; a version-1 file (5/3 everywhere) is refused with a clear message
    from volviz.regular.container import crc32
    path = tmp_path / "v1.vvz"
    compress(RegularVolume(_smooth_volume((20, 20, 20))), path)
    raw = bytearray(path.read_bytes())
    assert struct.unpack("<H", raw[8:10])[0] == 2
    raw[8:10] = struct.pack("<H", 1)
    raw[60:64] = struct.pack("<I", crc32(bytes(raw[:60])))
    path.write_bytes(bytes(raw))
    with pytest.raises(VVZError, match=r"v1\.vvz.*version 1 is not supported.*compress the volume again"):
        decompress(path)
