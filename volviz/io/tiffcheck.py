"""A TIFF's structure checked before tifffile or Pillow interprets it (issue #32).

tifffile and Pillow trust the directory: a damaged file ended in ``IndexError: tuple index out of range``,
``ZeroDivisionError``, zlib's words or an echo of the damaged ImageDescription. This walk follows the TIFF 6.0
specification (Adobe, 1992: section 2 "TIFF Structure", the image file header, IFDs and their 12-byte entries;
section 3 the baseline tags) and BigTIFF (8-byte offsets, 20-byte entries), and refuses, naming the page, the tag
and both values: an IFD or a value beyond the end of the file, an IFD chain that loops, a field type TIFF does not
define, a zero image size, rows per strip or bits per sample, strip or tile offsets and byte counts that differ in
number or run past the end of the file, and tifffile's JSON shape description (``{"shape": [...]}``) that is not
JSON with a list of sizes.
"""
from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

from volviz.io.errors import ReadError

#: TIFF field type -> bytes per value (1 BYTE .. 12 DOUBLE, 13 IFD; BigTIFF 16 LONG8, 17 SLONG8, 18 IFD8)
_TYPE_SIZES = {1: 1, 2: 1, 3: 2, 4: 4, 5: 8, 6: 1, 7: 1, 8: 2, 9: 4, 10: 8, 11: 4, 12: 8, 13: 4, 16: 8, 17: 8, 18: 8}
_FORMATS = {1: "B", 3: "H", 4: "I", 6: "b", 8: "h", 9: "i", 13: "I", 16: "Q", 17: "q", 18: "Q"}
MAX_PAGES = 1_000_000
MAX_ENTRIES = 4096
_WIDTH, _LENGTH, _BITS, _DESCRIPTION, _STRIPS, _SAMPLES, _ROWS, _STRIP_BYTES = 256, 257, 258, 270, 273, 277, 278, 279
_TILE_WIDTH, _TILE_LENGTH, _TILES, _TILE_BYTES = 322, 323, 324, 325


def _fail(path: Path, text: str) -> ReadError:
    return ReadError(path, f"TIFF {text}: the file is damaged")


def _entries(path: Path, data: Any, at: int, big: bool, order: str, page: int) -> tuple[dict[int, list], int]:
    """The integer values of one IFD's tags (others as their byte count), and the next IFD's offset."""
    size = len(data)
    count_fmt, entry, word = ("Q", 20, 8) if big else ("H", 12, 4)
    head = struct.calcsize(count_fmt)
    if at + head > size:
        raise _fail(path, f"page {page}: its directory at byte {at} lies beyond the end of the file ({size} bytes)")
    (count,) = struct.unpack_from(order + count_fmt, data, at)
    end = at + head + count * entry + word
    if count == 0 or count > MAX_ENTRIES or end > size:
        raise _fail(path, f"page {page}: its directory at byte {at} claims {count} entries, which "
                          f"{'run past the end of the file' if end > size else 'is not 1 to 4096'}")
    tags: dict[int, list] = {}
    for i in range(count):
        pos = at + head + i * entry
        tag, kind = struct.unpack_from(order + "HH", data, pos)
        (n,) = struct.unpack_from(order + ("Q" if big else "I"), data, pos + 4)
        if kind not in _TYPE_SIZES:
            raise _fail(path, f"page {page}: tag {tag} has field type {kind}, which TIFF does not define")
        nbytes = n * _TYPE_SIZES[kind]
        if nbytes <= word:
            where = pos + 4 + word
        else:
            (where,) = struct.unpack_from(order + ("Q" if big else "I"), data, pos + 4 + word)
            if where + nbytes > size:
                raise _fail(path, f"page {page}: tag {tag}'s {n} values ({nbytes} bytes at byte {where}) run past "
                                  f"the end of the file ({size} bytes)")
        fmt = _FORMATS.get(kind)
        if fmt is not None and tag in (_WIDTH, _LENGTH, _BITS, _SAMPLES, _ROWS, _STRIPS, _STRIP_BYTES, _TILE_WIDTH,
                                       _TILE_LENGTH, _TILES, _TILE_BYTES):
            tags[tag] = list(struct.unpack_from(f"{order}{n}{fmt}", data, where))
        elif tag == _DESCRIPTION and kind == 2:
            tags[tag] = [bytes(data[where:where + nbytes])]
    (nxt,) = struct.unpack_from(order + ("Q" if big else "I"), data, at + head + count * entry)
    return tags, nxt


def _check_image(path: Path, tags: dict[int, list], page: int, size: int) -> None:
    """A page's sizes, and its strips or tiles against each other and the file."""
    missing = [what for tag, what in ((_WIDTH, "ImageWidth"), (_LENGTH, "ImageLength")) if tag not in tags]
    if missing:
        raise _fail(path, f"page {page}: it lacks {' and '.join(missing)}")
    for tag, what in ((_WIDTH, "ImageWidth"), (_LENGTH, "ImageLength"), (_ROWS, "RowsPerStrip"),
                      (_SAMPLES, "SamplesPerPixel"), (_TILE_WIDTH, "TileWidth"), (_TILE_LENGTH, "TileLength")):
        if tag in tags and (len(tags[tag]) != 1 or tags[tag][0] <= 0):
            raise _fail(path, f"page {page}: {what} is {tags[tag][:4]}, not one positive number")
    bits = tags.get(_BITS, [1])
    if not bits or any(b <= 0 or b > 64 for b in bits):
        raise _fail(path, f"page {page}: BitsPerSample is {bits[:4]}, not 1 to 64")
    for offsets, counts, what in ((_STRIPS, _STRIP_BYTES, "strip"), (_TILES, _TILE_BYTES, "tile")):
        if offsets not in tags and counts not in tags:
            continue
        starts, lengths = tags.get(offsets, []), tags.get(counts, [])
        if len(starts) != len(lengths):
            raise _fail(path, f"page {page}: {len(starts)} {what} offsets but {len(lengths)} {what} byte counts")
        for k, (start, length) in enumerate(zip(starts, lengths)):
            if start < 0 or length < 0 or start + length > size:
                raise _fail(path, f"page {page}: {what} {k} of {length} bytes at byte {start} runs past the end of "
                                  f"the file ({size} bytes)")
    if _DESCRIPTION in tags and page == 0 and tags[_DESCRIPTION][0].startswith(b'{"shape"'):
        text = tags[_DESCRIPTION][0].rstrip(b"\0")
        try:
            shape = json.loads(text.decode("utf-8"))["shape"]
            ok = isinstance(shape, list) and all(isinstance(n, int) and n >= 0 for n in shape)
        except (ValueError, KeyError, TypeError):
            ok = False
        if not ok:
            raise _fail(path, "page 0: its ImageDescription (tifffile's shape) is not JSON with a list of sizes")


def check_tiff(path: Path, data: Any) -> None:
    """Refuse a TIFF (``data``: its bytes, or a map of them) whose structure does not hold (see the module)."""
    size = len(data)
    if size < 8:
        raise _fail(path, f"header: the file holds {size} bytes, the header alone needs 8")
    order = {b"II": "<", b"MM": ">"}.get(bytes(data[:2]))
    (magic,) = struct.unpack_from((order or "<") + "H", data, 2)
    if order is None or magic not in (42, 43):
        raise _fail(path, "header: it starts neither with II nor MM and 42 or 43")
    big = magic == 43
    if big:
        if size < 16 or struct.unpack_from(order + "HH", data, 4) != (8, 0):
            raise _fail(path, "header: a BigTIFF's offset size is not 8")
        (at,) = struct.unpack_from(order + "Q", data, 8)
    else:
        (at,) = struct.unpack_from(order + "I", data, 4)
    seen: set[int] = set()
    page = 0
    while at:
        if at < (16 if big else 8):
            raise _fail(path, f"page {page}: its directory offset {at} points into the file's header")
        if at in seen:
            raise _fail(path, f"page {page}: its directory at byte {at} is that of an earlier page (the chain loops)")
        if page >= MAX_PAGES:
            raise _fail(path, f"more than {MAX_PAGES} pages")
        seen.add(at)
        tags, at = _entries(path, data, at, big, order, page)
        _check_image(path, tags, page, size)
        page += 1
