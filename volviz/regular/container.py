"""The ``.vvz`` container for wavelet-compressed regular volumes (Guthe §2.3: one record per octree node).

Layout (all integers little-endian)::

    offset 0   fixed header, 64 bytes
        0  magic      8s   b"VVZ\\x00\\r\\n\\x1a\\n"
        8  version    u16  (2; version 1 files -- before the per-brick transform field -- are refused)
        10 hdr_size   u16  (64)
        12 flags      u32  (0)
        16 meta_off   u64  metadata: UTF-8 JSON object (see codec.py for the keys)
        24 meta_len   u64  (<= 1 MiB, nesting <= 4)
        32 table_off  u64  brick table: table_count records of 32 bytes
        40 table_count u64
        48 meta_crc   u32  CRC32 of the metadata bytes
        52 table_crc  u32  CRC32 of the brick table bytes
        56 reserved   u32  (0)
        60 hdr_crc    u32  CRC32 of bytes 0..59
    offset 64  brick payloads, in write order
    then       metadata JSON, then the brick table

    brick record (32 bytes): level u8 | kind u8 (0 root, 1 node) | transform u16 | tile u32 (x-fastest index of the
    tile within its level) | offset u64 | size u64 (0 = stripped all-zero node, no payload) | crc32 u32 | reserved u32

    transform (version 2): the wavelet of this node's one level, 0 = integer 5/3 lifting (the default, and the only
    one in lossy files), 1 = integer Haar / S-transform (lossless files: chosen per node by coded size, see
    ``wavelet.py``); 0 for the root. A stripped node (size 0) still records its transform: its children are the
    zero-detail inverse of that transform (5/3: linear interpolation, S-transform: constant 2x2x2 blocks).

Reading never executes or unpickles anything: the metadata is JSON, the table a fixed numpy record layout, and every
size and offset is checked against the file size before anything is allocated; the metadata's length and nesting
are bounded before it is parsed, and its fields (dtype from an allow-list, dims, sizes) are checked against each other
and against the brick table, whose payloads must tile the payload area exactly (:func:`check_meta`,
:func:`check_table`). Each brick carries its own CRC32, so
a damaged brick is found, named and skipped while the others decode. Writing is atomic (temporary file in the target
directory, fsync, rename).
"""
from __future__ import annotations

import json
import math
import os
import struct
import zlib
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from volviz.io._checks import describe_bytes
from volviz.io.jsonbounds import nesting_depth, outside_strings
from volviz.io.atomic import check_output_path, remove_stale_temporaries, temp_name
from volviz.io.errors import ReadError

MAGIC = b"VVZ\x00\r\n\x1a\n"
VERSION = 2
HEADER_SIZE = 64
MAX_META = 1 << 20           # bytes of the metadata JSON (a written one is under 1 KB)
MAX_META_DEPTH = 4          # nesting of its lists and objects (a written one nests 2 deep)
#: the sample types the codec writes, and the "kind" it records beside each (codec._Source)
DTYPE_KINDS = {"uint8": "uint8", "int8": "int8", "uint16": "uint16", "int16": "int16", "bool": "int-quantised",
               "uint32": "int-quantised", "int32": "int-quantised", "uint64": "int-quantised",
               "int64": "int-quantised", "float16": "float", "float32": "float", "float64": "float"}
MAX_DIM = 1 << 20
_HDR = struct.Struct("<8sHHIQQQQIII")
BRICK_DTYPE = np.dtype([("level", "<u1"), ("kind", "<u1"), ("transform", "<u2"), ("tile", "<u4"), ("offset", "<u8"),
                        ("size", "<u8"), ("crc", "<u4"), ("res1", "<u4")])
KIND_ROOT = 0
KIND_NODE = 1
assert _HDR.size == 60 and BRICK_DTYPE.itemsize == 32


class VVZError(ReadError):
    """A ``.vvz`` file that cannot be read; the message names the file and the problem."""


class CorruptBrickError(VVZError):
    """A brick failed its checksum (raised only in strict mode)."""


class CorruptBrickWarning(UserWarning):
    """Some bricks failed their checksum; their regions were filled from the coarser level."""


def crc32(data: Any) -> int:
    return zlib.crc32(memoryview(data)) & 0xFFFFFFFF


class Writer:
    """Streams bricks into a temporary file next to ``path``; :meth:`close` writes metadata, table and header,
    fsyncs and renames atomically. Use as a context manager (an exception removes the temporary file)."""

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = check_output_path(path)  # a regular file or nothing: never a device, FIFO or symlink
        remove_stale_temporaries(self.path.parent, self.path)  # of writes killed before their rename
        self._tmp = temp_name(self.path)
        self._f: BinaryIO = open(self._tmp, "x+b")
        self._f.write(b"\0" * HEADER_SIZE)
        self._pos = HEADER_SIZE
        self._records: list[tuple[int, int, int, int, int, int, int]] = []

    def add(self, level: int, kind: int, tile: int, payload: Any, transform: int = 0) -> None:
        data = memoryview(payload).cast("B")
        size = data.nbytes
        crc = crc32(data) if size else 0
        if size:
            self._f.write(data)
        self._records.append((level, kind, tile, self._pos if size else 0, size, crc, transform))
        self._pos += size

    @property
    def payload_bytes(self) -> int:
        return self._pos - HEADER_SIZE

    def close(self, meta: dict[str, Any]) -> int:
        meta_bytes = json.dumps(meta, sort_keys=True, allow_nan=False).encode("utf-8")
        table = np.zeros(len(self._records), BRICK_DTYPE)
        if self._records:
            rec = np.array(self._records, dtype=np.int64)
            table["level"], table["kind"], table["tile"] = rec[:, 0], rec[:, 1], rec[:, 2]
            table["offset"], table["size"], table["crc"] = rec[:, 3], rec[:, 4], rec[:, 5]
            table["transform"] = rec[:, 6]
        table_bytes = table.tobytes()
        meta_off = self._pos
        table_off = meta_off + len(meta_bytes)
        self._f.write(meta_bytes)
        self._f.write(table_bytes)
        head = _HDR.pack(MAGIC, VERSION, HEADER_SIZE, 0, meta_off, len(meta_bytes), table_off, len(table),
                         crc32(meta_bytes), crc32(table_bytes), 0)
        head = head + struct.pack("<I", crc32(head))
        self._f.seek(0)
        self._f.write(head + b"\0" * (HEADER_SIZE - len(head)))
        self._f.flush()
        os.fsync(self._f.fileno())
        self._f.close()
        os.replace(self._tmp, self.path)
        try:
            dfd = os.open(self.path.parent if str(self.path.parent) else ".", os.O_RDONLY)
            try:
                os.fsync(dfd)
            finally:
                os.close(dfd)
        except OSError:  # pragma: no cover - directories cannot be fsynced on some platforms
            pass
        return table_off + len(table_bytes)

    def abort(self) -> None:
        if not self._f.closed:
            self._f.close()
        self._tmp.unlink(missing_ok=True)

    def __enter__(self) -> "Writer":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if exc_type is not None:
            self.abort()


def parse_header(head: bytes, file_size: int, name: str = "<vvz>") -> dict[str, int]:
    """Validate the fixed 64-byte header against the file size; return its fields. Raises :class:`VVZError`."""
    if len(head) < HEADER_SIZE or file_size < HEADER_SIZE:
        raise VVZError(name, f"truncated file ({file_size} bytes, a .vvz header alone is {HEADER_SIZE})")
    if head[:8] != MAGIC:
        raise VVZError(name, f"not a .vvz file: it starts with {describe_bytes(head)}, not the .vvz signature")
    (_, version, hdr_size, flags, meta_off, meta_len, table_off, table_count, meta_crc, table_crc,
     _) = _HDR.unpack(head[:60])
    if crc32(head[:60]) != struct.unpack("<I", head[60:64])[0]:
        raise VVZError(name, "header checksum mismatch (damaged header)")
    if version != VERSION:
        raise VVZError(name, f".vvz version {version} is not supported (this reader knows version {VERSION}); "
                       "compress the volume again")
    if hdr_size != HEADER_SIZE:
        raise VVZError(name, f"bad header size {hdr_size}")
    if meta_len > MAX_META:
        raise VVZError(name, f"header field meta_len is {meta_len} bytes; .vvz metadata is at most {MAX_META}")
    if meta_off < HEADER_SIZE or meta_off + meta_len > file_size:
        raise VVZError(name, f"metadata block ({meta_len} bytes at {meta_off}) lies outside the file "
                       f"({file_size} bytes): truncated or damaged")
    if table_count == 0:
        raise VVZError(name, "header field table_count is 0; a .vvz holds at least its root brick")
    if table_count > file_size // BRICK_DTYPE.itemsize or table_off < HEADER_SIZE or \
            table_off + table_count * BRICK_DTYPE.itemsize > file_size:
        raise VVZError(name, f"brick table ({table_count} records at {table_off}) lies outside the file "
                       f"({file_size} bytes): truncated or damaged")
    return dict(version=version, flags=flags, meta_off=meta_off, meta_len=meta_len, table_off=table_off,
                table_count=table_count, meta_crc=meta_crc, table_crc=table_crc)


def parse_meta(data: bytes, name: str = "<vvz>") -> dict[str, Any]:
    """The metadata JSON object, its nesting bounded before ``json`` recurses into it. Raises :class:`VVZError`."""
    depth = nesting_depth(outside_strings(data))
    if depth > MAX_META_DEPTH:
        raise VVZError(name, f"metadata nests lists and objects {depth} deep; .vvz metadata nests at most "
                       f"{MAX_META_DEPTH}")
    try:
        meta = json.loads(data.decode("utf-8"), parse_constant=_no_constant)
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError is a ValueError
        raise VVZError(name, f"metadata is not valid JSON ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != "volviz-vvz":
        raise VVZError(name, "metadata is not a volviz-vvz object")
    return meta


def _no_constant(word: str) -> None:
    raise ValueError(f"{word} is not a number")


def _field(meta: dict[str, Any], key: str, name: str, kind: type | tuple[type, ...], what: str,
           ok: Any = lambda v: True, default: Any = ...) -> Any:
    """``meta[key]`` if it is of type ``kind`` (never a bool for numbers) and ``ok``; else a VVZError naming the
    field, its value and what it should be."""
    if key not in meta and default is not ...:
        return default
    value = meta.get(key)
    typed = isinstance(value, kind) and not (isinstance(value, bool) and bool not in (kind if isinstance(
        kind, tuple) else (kind,)))
    if not typed or not ok(value):
        shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
        raise VVZError(name, f"metadata field {key!r} is {shown if key in meta else 'missing'}; expected {what}")
    return value


def _finite(v: Any) -> bool:
    try:
        return math.isfinite(v)
    except OverflowError:  # an integer too large for a float
        return False


def check_meta(meta: dict[str, Any], payload_bytes: int, name: str = "<vvz>") -> None:
    """The metadata fields the decoder trusts, checked against each other and against the file: dims, dtype (from
    :data:`DTYPE_KINDS`) and the kind the codec records with it, the original and payload sizes, levels, tile,
    delta, value range, spacing, origin and name. Raises :class:`VVZError` naming the field and both values."""
    dims = _field(meta, "dims", name, list, f"3 integers from 1 to {MAX_DIM}", lambda v: len(v) == 3 and all(
        isinstance(d, int) and not isinstance(d, bool) and 1 <= d <= MAX_DIM for d in v))
    dtype = _field(meta, "dtype", name, str, "one of " + ", ".join(DTYPE_KINDS), lambda v: v in DTYPE_KINDS)
    kind = _field(meta, "kind", name, str, "a sample kind")
    if kind != DTYPE_KINDS[dtype]:
        raise VVZError(name, f"metadata field 'kind' is {kind!r} but 'dtype' is {dtype!r} (the codec writes kind "
                       f"{DTYPE_KINDS[dtype]!r} for {dtype})")
    expected = int(np.prod(dims, dtype=np.int64)) * np.dtype(dtype).itemsize
    _field(meta, "original_bytes", name, int, f"{expected} (dims {dims} of {dtype})", lambda v: v == expected)
    _field(meta, "payload_bytes", name, int, f"{payload_bytes} (the bytes between the header and the metadata)",
           lambda v: v == payload_bytes)
    _field(meta, "levels", name, int, "an integer from 0 to 20", lambda v: 0 <= v <= 20)
    _field(meta, "tile", name, int, "a positive integer", lambda v: v > 0)
    _field(meta, "coder", name, str, "a coder name")
    _field(meta, "coder_version", name, int, "a positive integer", lambda v: v > 0, default=1)
    _field(meta, "delta", name, (int, float), "a finite number >= 0", lambda v: _finite(v) and v >= 0)
    if kind in ("float", "int-quantised"):
        lo = _field(meta, "float_lo", name, (int, float), "a finite number", _finite)
        _field(meta, "float_hi", name, (int, float), f"a finite number >= float_lo ({lo})",
               lambda v: _finite(v) and v >= lo)
    _field(meta, "spacing", name, list, "3 finite numbers > 0", lambda v: len(v) == 3 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and _finite(x) and x > 0 for x in v), default=None)
    _field(meta, "origin", name, list, "3 finite numbers", lambda v: len(v) == 3 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and _finite(x) for x in v), default=None)
    _field(meta, "name", name, str, "a name of at most 1024 characters", lambda v: len(v) <= 1024, default=None)
    check_described(meta, kind, name)


#: every key the codec writes (``codec.compress``); any other key is refused, so ``volviz info`` shows none unchecked
META_KEYS = frozenset(("format", "dims", "dtype", "kind", "levels", "tile", "coder", "coder_version", "mode", "delta",
                       "quality", "psnr_target", "psnr", "psnr_scope", "lossless", "peak", "transform", "float_lo",
                       "float_hi", "spacing", "origin", "name", "original_bytes", "payload_bytes"))
#: the PSNR's peak the codec records per sample kind (the type's range; 65535 for the quantised kinds)
PEAKS = {"uint8": 255, "int8": 255, "uint16": 65535, "int16": 65535, "float": 65535, "int-quantised": 65535}
PSNR_SCOPES = ("volume", "central 256^3 crop")
_LOSSLESS_TRANSFORMS = ("auto", "5/3", "haar")


def _number(lo: float, hi: float) -> Any:
    return lambda v: _finite(v) and lo <= v <= hi


def check_described(meta: dict[str, Any], kind: str, name: str = "<vvz>") -> None:
    """The fields that describe how the file was made, which the decoder does not use but ``volviz info`` shows:
    known keys only; ``mode`` and ``lossless`` agree with the quantiser step ``delta`` (0 exactly when lossless, and
    ``2 ** ((90 - quality) / 10)`` in quality mode: Guthe §2.2.2's dead-zone step from the quality knob); the
    quality, PSNR target and measured PSNR in their ranges (a lossless file measures none); the PSNR's scope; the
    peak of the sample kind; the wavelet choice (lossy files: 5/3). Raises :class:`VVZError` naming the field, its
    value and what it should be (files of older writers lack some of these keys: each is then not checked)."""
    unknown = sorted(k for k in meta if k not in META_KEYS)
    if unknown:
        raise VVZError(name, f"metadata field {unknown[0][:60]!r} is not a .vvz metadata field (known: "
                       f"{', '.join(sorted(META_KEYS))})")
    delta = meta["delta"]
    mode = _field(meta, "mode", name, str, "lossless, quality or psnr", lambda v: v in ("lossless", "quality", "psnr"),
                  default=None)
    _field(meta, "lossless", name, bool, f"{str(delta == 0).lower()} (delta is {delta})", lambda v: v == (delta == 0),
           default=None)
    if mode == "lossless" and delta != 0:
        raise VVZError(name, f"metadata field 'delta' is {delta}; expected 0 in a file of mode 'lossless'")
    quality = _field(meta, "quality", name, (int, float, type(None)), "null or a number from 0 to 100",
                     lambda v: v is None or _number(0, 100)(v), default=None)
    if mode == "quality":
        if quality is None:
            raise VVZError(name, "metadata field 'quality' is None; expected a number from 0 to 100 in a file of mode "
                           "'quality'")
        step = 2.0 ** ((90.0 - quality) / 10.0)
        if not math.isclose(delta, step, rel_tol=1e-9):
            raise VVZError(name, f"metadata field 'delta' is {delta}; expected {step} (quality {quality})")
    target = _field(meta, "psnr_target", name, (int, float, type(None)), "null or a number of dB from 0 to 1000",
                    lambda v: v is None or (_number(0, 1000)(v) and v > 0), default=None)
    if mode == "psnr" and target is None:
        raise VVZError(name, "metadata field 'psnr_target' is None; expected a number of dB in a file of mode 'psnr'")
    _field(meta, "psnr", name, (int, float, type(None)), "null (lossless)" if delta == 0 else
           "null or a number of dB from 0 to 1000", lambda v: v is None or (delta != 0 and _number(0, 1000)(v)),
           default=None)
    _field(meta, "psnr_scope", name, str, " or ".join(PSNR_SCOPES), lambda v: v in PSNR_SCOPES, default=None)
    _field(meta, "peak", name, (int, float), f"{PEAKS[kind]} (the peak of kind {kind!r})",
           lambda v: v == PEAKS[kind], default=None)
    _field(meta, "transform", name, str, "auto, 5/3 or haar" if delta == 0 else "5/3 (a lossy file)",
           lambda v: v in (_LOSSLESS_TRANSFORMS if delta == 0 else ("5/3",)), default=None)


def check_table(table: np.ndarray, meta_off: int, name: str = "<vvz>") -> None:
    """The brick table as the writer makes it: kinds 0 or 1; payloads back to back from the header to the metadata
    in table order (so no size or offset can be changed unnoticed); a stripped node (size 0) has offset and crc 0.
    Raises :class:`VVZError` naming the brick, the field and both values."""
    def brick(i: int) -> str:
        return f"brick {i} (level {int(table[i]['level'])}, tile {int(table[i]['tile'])})"

    bad = np.nonzero(table["kind"] > KIND_NODE)[0]
    if bad.size:
        raise VVZError(name, f"{brick(int(bad[0]))} field kind is {int(table[bad[0]]['kind'])}; expected "
                       f"{KIND_ROOT} (root) or {KIND_NODE} (node)")
    bad = np.nonzero(table["res1"] != 0)[0]
    if bad.size:
        raise VVZError(name, f"{brick(int(bad[0]))} field reserved is {int(table[bad[0]]['res1'])}; expected 0")
    bad = np.nonzero((table["kind"] == KIND_ROOT) & (table["transform"] != 0))[0]
    if bad.size:
        raise VVZError(name, f"{brick(int(bad[0]))} field transform is {int(table[bad[0]]['transform'])}; the root "
                       "brick's is 0")
    sizes = table["size"].astype(np.uint64)
    if sizes.max() > np.uint64(meta_off):
        i = int(np.argmax(sizes))
        raise VVZError(name, f"{brick(i)} field size is {int(sizes[i])} bytes, but the payload area holds "
                       f"{meta_off - HEADER_SIZE}")
    stripped = sizes == 0
    bad = np.nonzero(stripped & ((table["offset"] != 0) | (table["crc"] != 0)))[0]
    if bad.size:
        i = int(bad[0])
        raise VVZError(name, f"{brick(i)} field size is 0 (a stripped node) but its offset is "
                       f"{int(table[i]['offset'])} and crc {int(table[i]['crc'])}; a stripped node has both 0")
    starts = HEADER_SIZE + np.concatenate(([0], np.cumsum(sizes, dtype=np.uint64)[:-1]))
    bad = np.nonzero(~stripped & (table["offset"].astype(np.uint64) != starts))[0]
    if bad.size:
        i = int(bad[0])
        raise VVZError(name, f"{brick(i)} field offset is {int(table[i]['offset'])}, but the bricks before it end "
                       f"at {int(starts[i])}")
    total = int(sizes.sum(dtype=np.uint64))
    if total != meta_off - HEADER_SIZE:
        raise VVZError(name, f"brick table sizes add up to {total} bytes, but the payload area holds "
                       f"{meta_off - HEADER_SIZE} (from byte {HEADER_SIZE} to the metadata at {meta_off})")


class Reader:
    """Read-only view of a ``.vvz`` file: validated header, metadata dict, brick table and payload access."""

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        name = str(self.path)
        try:
            self.file_size = self.path.stat().st_size
            with open(self.path, "rb") as f:
                head = f.read(HEADER_SIZE)
                h = parse_header(head, self.file_size, name)
                f.seek(h["meta_off"])
                meta_bytes = f.read(h["meta_len"])
                f.seek(h["table_off"])
                table_bytes = f.read(h["table_count"] * BRICK_DTYPE.itemsize)
        except OSError as exc:
            raise VVZError(name, f"cannot read ({exc})") from exc
        if crc32(meta_bytes) != h["meta_crc"]:
            raise VVZError(name, "metadata checksum mismatch (damaged metadata)")
        if crc32(table_bytes) != h["table_crc"]:
            raise VVZError(name, "brick table checksum mismatch (damaged table)")
        self.header = h
        self.meta: dict[str, Any] = parse_meta(meta_bytes, name)
        self.table = np.frombuffer(table_bytes, BRICK_DTYPE)
        check_table(self.table, h["meta_off"], name)
        check_meta(self.meta, h["meta_off"] - HEADER_SIZE, name)
        self._map: np.ndarray | None = None

    @property
    def payload(self) -> np.ndarray:
        """The whole file as a read-only uint8 memory map (brick offsets index into it)."""
        if self._map is None:
            self._map = np.memmap(self.path, dtype=np.uint8, mode="r")
        return self._map

    def brick_ok(self, index: int) -> bool:
        rec = self.table[index]
        size = int(rec["size"])
        if size == 0:
            return int(rec["crc"]) == 0
        off = int(rec["offset"])
        return crc32(self.payload[off:off + size]) == int(rec["crc"])

    def close(self) -> None:
        if self._map is not None:
            mm = getattr(self._map, "_mmap", None)
            self._map = None
            if mm is not None:
                try:
                    mm.close()
                except BufferError:  # still referenced by a caller's view
                    pass
