"""A MAT-file v5 / v7's element structure checked before SciPy interprets it (issue #32).

SciPy trusts the tags: a damaged size or dimension made ``loadmat`` raise ``IndexError``, report a zlib error in
zlib's words, or crash the process (a data size of 0 under a 6x7x5 array: segmentation fault). This walk follows
the MAT-File Format reference (MathWorks, "MAT-File Format", ch. 1: 128-byte header, 8-byte tags, small data
elements, miMATRIX subelements, miCOMPRESSED zlib streams) and refuses, naming the variable, the field and both
values: a tag that runs past its container, an unknown data type, dimensions that are negative or fewer than two,
a numeric array whose data size is not its element count times the size of its stored type, a struct whose field
names do not divide into its name length, and nesting deeper than :data:`MAX_DEPTH`. Compressed variables are
decompressed as a stream (the bytes already walked are dropped), so a check holds at most one read chunk.
"""
from __future__ import annotations

import math
import re
import mmap
import struct
import zlib
from pathlib import Path

from volviz.io.errors import ReadError

MAX_DEPTH = 32
_CHUNK = 1 << 20
#: data type -> bytes per element (miINT8 .. miUTF32; 14 miMATRIX and 15 miCOMPRESSED are containers)
_SIZES = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 9: 8, 12: 8, 13: 8, 16: 1, 17: 2, 18: 4}
_NUMERIC_CLASSES = set(range(6, 16))  # mxDOUBLE_CLASS .. mxUINT64_CLASS
_CELL, _STRUCT, _OBJECT, _CHAR = 1, 2, 3, 4


class _Bytes:
    """Forward-only access to a byte source: the file's bytes, or a zlib stream decompressed as far as asked."""

    def __init__(self, data: bytes | mmap.mmap, compressed: bool = False) -> None:
        self.raw, self.compressed = data, compressed
        self.buf: bytes | mmap.mmap = b"" if compressed else data   # the plain stream: the bytes themselves
        self.base = 0
        self.inflater = zlib.decompressobj() if compressed else None
        self.fed = 0

    def get(self, pos: int, count: int) -> bytes:
        """``count`` bytes at ``pos`` (fewer at the end); bytes before ``pos`` are no longer kept."""
        if not self.compressed:
            return self.raw[pos:pos + count]
        while True:
            drop = min(len(self.buf), pos - self.base)
            self.buf, self.base = self.buf[drop:], self.base + drop
            if self.base + len(self.buf) >= pos + count or not self._more():
                return self.buf[pos - self.base:pos - self.base + count]

    def _more(self) -> bool:
        """Decompress one more chunk into the buffer; False at the end of the stream or of its input."""
        if self.inflater is None:   # a plain stream: ``read`` slices the bytes themselves
            return False
        if self.inflater.eof:
            return False
        if self.inflater.unconsumed_tail:
            data = self.inflater.unconsumed_tail
        elif self.fed < len(self.raw):
            data, self.fed = self.raw[self.fed:self.fed + _CHUNK], self.fed + _CHUNK
        else:
            return False
        self.buf = bytes(self.buf) + self.inflater.decompress(data, _CHUNK)
        return True


class _Walk:
    def __init__(self, path: Path, order: str) -> None:
        self.path, self.order = path, order

    def fail(self, where: str, what: str) -> ReadError:
        return ReadError(self.path, f"MAT-file {where}: {what}")

    def tag(self, src: _Bytes, pos: int, end: int, where: str) -> tuple[int, int, int, int]:
        """(type, byte count, data start, next element) of the element at ``pos`` inside ``[pos, end)``."""
        head = src.get(pos, 8)
        if len(head) < 8:
            raise self.fail(where, f"an element tag at byte {pos} runs past the end of the data ({len(head)} bytes "
                                   "remain): the file is truncated or damaged")
        if pos + 8 > end:
            raise self.fail(where, f"an element tag at byte {pos} runs past the end of its container (byte {end})")
        first, count = struct.unpack(self.order + "II", head)
        if first >> 16:  # small data element: type and count in 4 bytes, data in the next 4
            kind, count, start, nxt = first & 0xFFFF, first >> 16, pos + 4, pos + 8
            if count > 4:
                raise self.fail(where, f"a small data element at byte {pos} claims {count} bytes (at most 4)")
        else:
            kind, start = first, pos + 8
            nxt = start + count + (-count % 8 if kind != 15 else 0)
        if kind not in _SIZES and kind not in (14, 15):
            raise self.fail(where, f"the element at byte {pos} has data type {kind}, which MAT-files do not define")
        if start + count > end:
            raise self.fail(where, f"the element at byte {pos} claims {count} bytes but its container ends "
                                   f"{end - start} bytes after its tag: the file is truncated or damaged")
        return kind, count, start, min(nxt, end)

    def data(self, src: _Bytes, pos: int, end: int, where: str, kinds: tuple[int, ...], what: str) -> tuple:
        """The values of a subelement of one of ``kinds`` (integers), and the next position."""
        kind, count, start, nxt = self.tag(src, pos, end, where)
        if kind not in kinds:
            raise self.fail(where, f"its {what} has data type {kind}, expected {' or '.join(map(str, kinds))}")
        size = _SIZES[kind]
        if count % size:
            raise self.fail(where, f"its {what} holds {count} bytes, not a whole number of {size}-byte values")
        fmt = {1: "b", 2: "B", 3: "h", 4: "H", 5: "i", 6: "I", 16: "B"}[kind]
        return struct.unpack(f"{self.order}{count // size}{fmt}", src.get(start, count)), nxt

    def matrix(self, src: _Bytes, start: int, end: int, where: str, depth: int) -> None:
        """The subelements of one miMATRIX occupying ``[start, end)``."""
        if depth > MAX_DEPTH:
            raise self.fail(where, f"cells or structs are nested deeper than {MAX_DEPTH} levels")
        if start == end:
            return  # an empty matrix
        flags, pos = self.data(src, start, end, where, (6,), "array flags")
        if len(flags) != 2:
            raise self.fail(where, f"its array flags hold {len(flags)} values, not 2")
        klass, complex_ = flags[0] & 0xFF, bool(flags[0] & 0x800)
        if not 1 <= klass <= 17:
            raise self.fail(where, f"its array class is {klass}, which MAT-files do not define (1 to 17)")
        dims, pos = self.data(src, pos, end, where, (5,), "dimensions")
        if len(dims) < 2 or min(dims) < 0:
            raise self.fail(where, f"its dimensions are {list(dims)}: at least two, none negative")
        name, pos = self.data(src, pos, end, where, (1, 2, 16), "name")
        label = bytes(n & 0xFF for n in name).decode("latin-1")
        if depth == 0:
            if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,62}", label):
                raise self.fail(where, f"its name ({len(name)} bytes) is not a MATLAB variable name")
            where = f"variable {label}"
        count = math.prod(dims)
        if klass in _NUMERIC_CLASSES:
            for part in ("real part", "imaginary part")[:1 + complex_]:
                kind, nbytes, _, pos = self.tag(src, pos, end, where)
                if kind not in _SIZES or kind in (16, 17, 18):
                    raise self.fail(where, f"its {part} has data type {kind}, not a numeric type")
                if nbytes != count * _SIZES[kind]:
                    raise self.fail(where, f"its {part} holds {nbytes} bytes but {'x'.join(map(str, dims))} "
                                           f"values of {_SIZES[kind]} bytes need {count * _SIZES[kind]}")
        elif klass == _CHAR:
            kind, nbytes, _, pos = self.tag(src, pos, end, where)
            if kind in _SIZES and kind != 16 and nbytes != count * _SIZES[kind]:
                raise self.fail(where, f"its characters hold {nbytes} bytes but {'x'.join(map(str, dims))} "
                                       f"characters of {_SIZES[kind]} bytes need {count * _SIZES[kind]}")
        elif klass in (_CELL, _STRUCT, _OBJECT):
            fields = 1
            if klass == _OBJECT:
                _, pos = self.data(src, pos, end, where, (1, 2), "class name")
            if klass != _CELL:
                length, pos = self.data(src, pos, end, where, (5,), "field name length")
                names, pos = self.data(src, pos, end, where, (1, 2), "field names")
                if len(length) != 1 or length[0] <= 0 or len(names) % length[0]:
                    raise self.fail(where, f"its field names hold {len(names)} bytes, not a whole number of "
                                           f"names of the length it gives ({list(length)})")
                fields = len(names) // length[0]
            for i in range(count * fields):
                kind, _, sub, pos = self.tag(src, pos, end, where)
                if kind != 14:
                    raise self.fail(where, f"element {i} of its {count * fields} cells or fields has data type "
                                           f"{kind}, not a matrix")
                self.matrix(src, sub, pos, where, depth + 1)


def check_mat5(path: Path, data: bytes | mmap.mmap) -> None:
    """Refuse a v5 / v7 MAT-file (``data``: the whole file) whose element structure does not hold (see the module).

    Sparse, function-handle and opaque (class) variables are checked only to fit their container."""
    if len(data) < 128:
        raise ReadError(path, f"MAT-file header: the file holds {len(data)} bytes, the header alone needs 128")
    order = {b"IM": "<", b"MI": ">"}.get(data[126:128])
    if order is None:
        raise ReadError(path, f"MAT-file header: the endian indicator is {data[126:128]!r}, not 'IM' or 'MI'")
    version = struct.unpack(order + "H", data[124:126])[0]
    if version != 0x0100:
        raise ReadError(path, f"MAT-file header: the version is {version:#06x}, not 0x0100 (level 5)")
    walk, pos = _Walk(path, order), 128
    raw = _Bytes(data)
    while pos < len(data):
        where = f"element at byte {pos}"
        kind, count, start, pos = walk.tag(raw, pos, len(data), "top level")
        if kind not in (14, 15) or count == 0:
            raise walk.fail(where, f"a variable has data type {kind} and {count} bytes: a top-level element is a "
                                   "matrix (14) or compressed (15) and holds bytes")
        if kind == 15:
            inner = _Bytes(data[start:start + count], compressed=True)
            try:
                sub_kind, sub_count, sub_start, _ = walk.tag(inner, 0, 1 << 62, where)
                if sub_kind == 14:
                    walk.matrix(inner, sub_start, sub_start + sub_count, where, 0)
            except zlib.error as exc:
                raise walk.fail(where, f"its zlib data is damaged ({exc})") from None
        elif kind == 14:
            walk.matrix(raw, start, start + count, where, 0)
