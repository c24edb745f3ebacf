"""Crafted .vvz files with consistent checksums (issue #32): every inconsistent metadata field or brick table entry
is refused with one line naming the file, the field and both values; nothing allocates what a header claims."""
from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

from volviz.cli import main
from volviz.model.datasets import RegularVolume
from volviz.regular.codec import compress, decompress, info
from volviz.regular.container import _HDR, BRICK_DTYPE, HEADER_SIZE, MAGIC, MAX_META, VERSION, VVZError, crc32


def _volume(shape=(40, 36, 34), dtype=np.uint8) -> np.ndarray:
    x, y, z = np.meshgrid(*[np.linspace(0, 3, n) for n in shape], indexing="ij")
    return (100 + 50 * np.sin(2 * x) * np.cos(3 * y) + 30 * np.sin(4 * z)).astype(dtype)


@pytest.fixture(scope="module")
def original(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("vvz") / "v.vvz"
    compress(RegularVolume(_volume()), path)
    return path


def _parts(raw: bytes) -> tuple[bytes, bytes, np.ndarray]:
    """payload area, metadata bytes and brick table of a .vvz file's bytes."""
    f = _HDR.unpack(raw[:60])
    meta_off, meta_len, table_off, count = f[4], f[5], f[6], f[7]
    table = np.frombuffer(raw[table_off:table_off + 32 * count], BRICK_DTYPE).copy()
    return raw[HEADER_SIZE:meta_off], raw[meta_off:meta_off + meta_len], table


def _assemble(payload: bytes, meta: bytes, table: np.ndarray, count: int | None = None,
              meta_len: int | None = None) -> bytes:
    """A .vvz file of these parts with every checksum recomputed (header fields overridable)."""
    meta_off = HEADER_SIZE + len(payload)
    table_off = meta_off + len(meta)
    tb = table.tobytes()
    head = _HDR.pack(MAGIC, VERSION, HEADER_SIZE, 0, meta_off, len(meta) if meta_len is None else meta_len,
                     table_off, len(table) if count is None else count, crc32(meta), crc32(tb), 0)
    head += struct.pack("<I", crc32(head))
    return head + payload + meta + tb


def _crafted(original: Path, tmp_path: Path, meta_edit: Callable[[dict[str, Any]], Any] | None = None,
             table_edit: Callable[[np.ndarray], Any] | None = None, meta_bytes: bytes | None = None) -> Path:
    payload, meta, table = _parts(original.read_bytes())
    if meta_edit is not None:
        doc = json.loads(meta)
        meta_edit(doc)
        meta = json.dumps(doc).encode()
    if table_edit is not None:
        table_edit(table)
    path = tmp_path / "crafted.vvz"
    path.write_bytes(_assemble(payload, meta_bytes if meta_bytes is not None else meta, table))
    return path


def _refused(path: Path, pattern: str) -> str:
    """Both the decoder and ``info`` refuse ``path`` with one line naming it that matches ``pattern``."""
    for call in (decompress, info):
        with pytest.raises(VVZError) as caught:
            call(path)
        text = str(caught.value)
        assert "\n" not in text and text.startswith(f"{path}: ")
        assert caught.match(pattern)
    return text


def test_an_unchanged_rebuild_reads_back(original, tmp_path):
    path = _crafted(original, tmp_path)
    assert path.read_bytes() == original.read_bytes()  # the helper rebuilds a written file byte for byte
    assert np.array_equal(decompress(path).data, _volume())


def test_a_huge_void_dtype_is_refused_without_allocating(original, tmp_path):
    path = _crafted(original, tmp_path, meta_edit=lambda m: m.update(dtype="V100000000"))
    _refused(path, r"metadata field 'dtype' is 'V100000000'; expected one of uint8, int8, .*, float64$")


def test_deeply_nested_metadata_is_refused_before_parsing(original, tmp_path):
    deep = b'{"format": "volviz-vvz", "x": ' + b"[" * 100_000 + b"]" * 100_000 + b"}"
    path = _crafted(original, tmp_path, meta_bytes=deep)
    _refused(path, r"metadata nests lists and objects 100001 deep; \.vvz metadata nests at most 4$")


def test_dtype_changed_to_int64_is_refused(original, tmp_path):
    path = _crafted(original, tmp_path, meta_edit=lambda m: m.update(dtype="int64"))
    _refused(path, r"metadata field 'kind' is 'uint8' but 'dtype' is 'int64' \(the codec writes kind "
                   r"'int-quantised' for int64\)")
    # with the kind changed too, the original size no longer fits the dims
    path = _crafted(original, tmp_path, meta_edit=lambda m: m.update(dtype="int64", kind="int-quantised"))
    _refused(path, r"metadata field 'original_bytes' is 48960; expected 391680 \(dims \[40, 36, 34\] of int64\)")


@pytest.mark.parametrize("field, value, pattern", [
    ("dims", [40, 36], r"'dims' is \[40, 36\]; expected 3 integers"),
    ("dims", [40, 36, 0], r"'dims' is \[40, 36, 0\]; expected 3 integers from 1"),
    ("dims", [40, 36, 1e300], r"'dims' is \[40, 36, 1e\+300\]"),
    ("payload_bytes", 0, r"'payload_bytes' is 0; expected \d+ \(the bytes between the header and the metadata\)"),
    ("levels", -1, r"'levels' is -1; expected an integer from 0 to 20"),
    ("tile", 0, r"'tile' is 0; expected a positive integer"),
    ("delta", "0", r"'delta' is '0'; expected a finite number >= 0"),
    ("spacing", [1, 0, 1], r"'spacing' is \[1, 0, 1\]; expected 3 finite numbers > 0"),
    ("origin", [1, 2, True], r"'origin' is \[1, 2, True\]; expected 3 finite numbers"),
    ("name", {"a": 1}, r"'name' is \{'a': 1\}; expected a name"),
    ("coder", None, r"'coder' is None; expected a coder name"),
    ("original_bytes", 10 ** 400, r"'original_bytes' is 1000000.*\.\.\.; expected 48960"),
])
def test_each_bad_metadata_field_is_named_with_its_value(original, tmp_path, field, value, pattern):
    path = _crafted(original, tmp_path, meta_edit=lambda m: m.update({field: value}))
    _refused(path, f"metadata field {pattern}")


def test_a_missing_field_is_named(original, tmp_path):
    path = _crafted(original, tmp_path, meta_edit=lambda m: m.pop("dtype"))
    _refused(path, r"metadata field 'dtype' is missing; expected one of")


def test_float_range_of_a_float_volume(tmp_path):
    src = tmp_path / "f.vvz"
    compress(RegularVolume(_volume(dtype=np.float32)), src)
    path = _crafted(src, tmp_path, meta_edit=lambda m: m.update(float_hi=m["float_lo"] - 1))
    _refused(path, r"metadata field 'float_hi' is [-\d.]+; expected a finite number >= float_lo \([-\d.]+\)$")
    nan = _parts(src.read_bytes())[1].replace(b'"float_lo": ', b'"float_lo": NaN, "x": ')
    path = _crafted(src, tmp_path, meta_bytes=nan)
    _refused(path, r"metadata is not valid JSON \(NaN is not a number\)")


def _first(table: np.ndarray, stripped: bool = False) -> int:
    return int(np.nonzero((table["size"] == 0) if stripped else (table["size"] > 0))[0][0])


def test_a_brick_size_set_to_zero_is_refused(original, tmp_path):
    def zero_size(t: np.ndarray) -> None:
        t["size"][_first(t)] = 0

    _refused(_crafted(original, tmp_path, table_edit=zero_size),
             r"brick 0 \(level 1, tile 0\) field size is 0 \(a stripped node\) but its offset is 64 and crc \d+; "
             r"a stripped node has both 0$")

    def strip(t: np.ndarray) -> None:  # made to look like a stripped node: the next brick no longer follows
        i = _first(t)
        t["size"][i] = t["offset"][i] = t["crc"][i] = 0

    _refused(_crafted(original, tmp_path, table_edit=strip), r"brick 1 \(level 1, tile 1\) field offset is \d+, "
                                                             r"but the bricks before it end at 64$")

    def strip_last(t: np.ndarray) -> None:  # the root, written last: the payload area is no longer covered
        t["size"][-1] = t["offset"][-1] = t["crc"][-1] = 0

    _refused(_crafted(original, tmp_path, table_edit=strip_last),
             r"brick table sizes add up to \d+ bytes, but the payload area holds \d+ \(from byte 64 to the metadata")


def test_brick_kind_and_oversize(original, tmp_path):
    _refused(_crafted(original, tmp_path, table_edit=lambda t: t["kind"].__setitem__(3, 7)),
             r"brick 3 \(level 1, tile 3\) field kind is 7; expected 0 \(root\) or 1 \(node\)")
    _refused(_crafted(original, tmp_path, table_edit=lambda t: t["size"].__setitem__(2, 1 << 40)),
             r"brick 2 \(level 1, tile 2\) field size is 1099511627776 bytes, but the payload area holds \d+$")


def test_header_table_count_zero_and_meta_len_bound(original, tmp_path):
    payload, meta, table = _parts(original.read_bytes())
    path = tmp_path / "h.vvz"
    path.write_bytes(_assemble(payload, meta, table, count=0))
    _refused(path, r"header field table_count is 0; a \.vvz holds at least its root brick$")
    path.write_bytes(_assemble(payload, meta, table, meta_len=MAX_META + 1))
    _refused(path, rf"header field meta_len is {MAX_META + 1} bytes; \.vvz metadata is at most {MAX_META}$")


def test_cli_info_refuses_a_crafted_file_as_a_user_error(original, tmp_path, capsys):
    path = _crafted(original, tmp_path, meta_edit=lambda m: m.update(dtype="V100000000"))
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"volviz: error: {path}: metadata field 'dtype' is 'V100000000'")
