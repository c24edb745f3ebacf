"""The ``.vvz`` container for wavelet-compressed regular volumes (Guthe §2.3: one record per octree node).

Layout (all integers little-endian)::

    offset 0   fixed header, 64 bytes
        0  magic      8s   b"VVZ\\x00\\r\\n\\x1a\\n"
        8  version    u16  (2; version 1 files -- before the per-brick transform field -- are refused)
        10 hdr_size   u16  (64)
        12 flags      u32  (0)
        16 meta_off   u64  metadata: UTF-8 JSON object (see codec.py for the keys)
        24 meta_len   u64  (<= 16 MiB)
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
size and offset is checked against the file size before anything is allocated. Each brick carries its own CRC32, so
a damaged brick is found, named and skipped while the others decode. Writing is atomic (temporary file in the target
directory, fsync, rename).
"""
from __future__ import annotations

import json
import os
import struct
import zlib
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from volviz.io._checks import describe_bytes
from volviz.io.atomic import check_output_path, remove_stale_temporaries, temp_name
from volviz.io.errors import ReadError

MAGIC = b"VVZ\x00\r\n\x1a\n"
VERSION = 2
HEADER_SIZE = 64
MAX_META = 16 << 20
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
        remove_stale_temporaries(self.path.parent)  # of earlier writes that were killed before their rename
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
    if meta_len > MAX_META or meta_off < HEADER_SIZE or meta_off + meta_len > file_size:
        raise VVZError(name, f"metadata block ({meta_len} bytes at {meta_off}) lies outside the file "
                       f"({file_size} bytes): truncated or damaged")
    if table_count > file_size // BRICK_DTYPE.itemsize or table_off < HEADER_SIZE or \
            table_off + table_count * BRICK_DTYPE.itemsize > file_size:
        raise VVZError(name, f"brick table ({table_count} records at {table_off}) lies outside the file "
                       f"({file_size} bytes): truncated or damaged")
    return dict(version=version, flags=flags, meta_off=meta_off, meta_len=meta_len, table_off=table_off,
                table_count=table_count, meta_crc=meta_crc, table_crc=table_crc)


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
        try:
            meta = json.loads(meta_bytes.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise VVZError(name, f"metadata is not valid JSON ({exc})") from exc
        if not isinstance(meta, dict) or meta.get("format") != "volviz-vvz":
            raise VVZError(name, "metadata is not a volviz-vvz object")
        self.header = h
        self.meta: dict[str, Any] = meta
        self.table = np.frombuffer(table_bytes, BRICK_DTYPE)
        end = self.table["offset"].astype(np.uint64) + self.table["size"].astype(np.uint64)
        bad = np.nonzero((self.table["size"] > 0) & ((self.table["offset"] < HEADER_SIZE) |
                                                      (end > np.uint64(h["meta_off"]))))[0]
        if bad.size:
            b = self.table[bad[0]]
            raise VVZError(name, f"brick {int(bad[0])} (level {int(b['level'])}, tile {int(b['tile'])}) points "
                           f"outside the payload area: truncated or damaged")
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
