"""Checks of a VTK legacy (.vtk) file before VTK's reader sees it: every count anywhere in the file.

VTK's legacy reader allocates what a count line asks for (``POINTS 2147483648 float``) and loops over what a
``FIELD`` line announces, so a lying count crashes or hangs it. Here the whole file is scanned (memory-mapped, read
by the operating system in pages, never copied whole) for the lines that carry counts, in file order:

- every count against the bytes left after its line (binary: the type's size per value; ASCII: a digit and a
  separator per value), so nothing is allocated that the file cannot hold;
- counts against each other: ``POINT_DATA`` against the points (``DIMENSIONS`` or ``POINTS``), ``CELL_DATA`` and
  ``CELL_TYPES`` against the cells, ``POINTS`` of a structured grid and the rectilinear coordinates against
  ``DIMENSIONS``;
- ``ORIGIN``, ``SPACING`` and ``ASPECT_RATIO`` finite numbers;
- each ``FIELD name n`` block walked array by array (``arrayName components tuples type`` then its data, skipped
  exactly in binary files and value by value in ASCII ones), so a block announcing more arrays than it holds is
  refused.

The title (line 2) may be any length, as VTK reads it.
"""
from __future__ import annotations

import mmap
import re
from typing import NoReturn

import numpy as np

from volviz.io._checks import describe_bytes, open_file
from volviz.io.errors import PathLike, ReadError, bytes_and_size

MAGIC = b"# vtk DataFile Version"
# bytes per value in a binary file (0: bits; None: strings, each with its own length); "long" as VTK reads it here
_TYPE_BYTES = {
    "bit": 0, "unsigned_char": 1, "char": 1, "signed_char": 1, "short": 2, "unsigned_short": 2, "int": 4,
    "unsigned_int": 4, "float": 4, "double": 8, "vtktypeint64": 8, "vtktypeuint64": 8, "vtkidtype": 4,
    "long": np.dtype("l").itemsize, "unsigned_long": np.dtype("L").itemsize, "string": None, "utf8_string": None,
}
_STRINGS = ("string", "utf8_string")
_KEYWORDS = (b"DATASET|DIMENSIONS|ORIGIN|SPACING|ASPECT_RATIO|POINTS|[XYZ]_COORDINATES|CELLS|POLYGONS|VERTICES|"
             b"LINES|TRIANGLE_STRIPS|CELL_TYPES|OFFSETS|CONNECTIVITY|POINT_DATA|CELL_DATA|SCALARS|COLOR_SCALARS|"
             b"LOOKUP_TABLE|VECTORS|NORMALS|TENSORS6|TENSORS|TEXTURE_COORDINATES|GLOBAL_IDS|PEDIGREE_IDS|FIELD")
_LINE = re.compile(rb"\n[ \t]*(" + _KEYWORDS + rb")(?![A-Za-z0-9_])([^\n]*)", re.I)
_COMPONENTS = {b"VECTORS": 3, b"NORMALS": 3, b"TENSORS": 9, b"TENSORS6": 6, b"GLOBAL_IDS": 1, b"PEDIGREE_IDS": 1}
_CELL_LISTS = (b"CELLS", b"POLYGONS", b"VERTICES", b"LINES", b"TRIANGLE_STRIPS")
_WHITESPACE = np.zeros(256, bool)
_WHITESPACE[list(b" \t\n\r\v\f")] = True
_CHUNK = 1 << 22


class _Scan:
    """State of one pass over the file: the format, the data set's sizes so far and the current attribute count."""

    def __init__(self, path: PathLike, mm: mmap.mmap, binary: bool, version: float) -> None:
        self.path, self.mm, self.size, self.binary, self.version = path, mm, len(mm), binary, version
        self.dataset = b""
        self.dims: list[int] | None = None
        self.points: int | None = None
        self.cells: int | None = None
        self.cell_lists = 0
        self.pending: dict[bytes, int] = {}  # OFFSETS / CONNECTIVITY counts announced by a version 5 CELLS line
        self.attribute: tuple[bytes, int] | None = None

    # -- helpers ----------------------------------------------------------------------------------------------------
    def fail(self, problem: str) -> NoReturn:
        raise ReadError(self.path, f"VTK legacy {problem}")

    def count(self, token: bytes, what: str) -> int:
        if not token.isdigit():
            self.fail(f"{what} is {describe_bytes(token)}, not a count")
        return int(token)

    def counts(self, args: list[bytes], n: int, what: str) -> list[int]:
        if len(args) < n:
            self.fail(f"{what} line holds {len(args)} fields, needs {n}")
        return [self.count(a, what) for a in args[:n]]

    def need(self, values: int, dtype: bytes, left: int, what: str) -> None:
        """Refuse ``values`` values of ``dtype`` that cannot fit in the ``left`` bytes after their line."""
        name = dtype.decode("ascii", "replace").lower()
        if self.binary:
            size = _TYPE_BYTES.get(name, 1)
            needed = -(-values // 8) if size == 0 else values * (size if size is not None else 1)
        else:
            needed = values if name in _STRINGS else max(2 * values - 1, 0)
        if needed > left:
            self.fail(f"{what} needs {bytes_and_size(needed)} but only {left} bytes remain in the "
                      "file: the count is wrong or the file is truncated")

    def agree(self, what: str, value: int, expected: int | None, source: str) -> None:
        if expected is not None and value != expected:
            self.fail(f"{what} is {value}, but {source} gives {expected}")

    def structured_cells(self) -> int | None:
        return None if self.dims is None else int(np.prod([max(d - 1, 1) for d in self.dims], dtype=object))

    # -- one keyword line -------------------------------------------------------------------------------------------
    def line(self, keyword: bytes, args: list[bytes], end: int) -> int:
        """Check one keyword line whose newline is at ``end`` (its data follows); returns where the scan goes on
        (``end``, or the end of a FIELD block)."""
        kw = keyword.upper()
        left = max(self.size - end - 1, 0)
        if kw == b"DATASET":
            self.dataset = args[0].upper() if args else b""
        elif kw == b"DIMENSIONS":
            self.dims = self.counts(args, 3, "DIMENSIONS")
            if min(self.dims) <= 0:
                self.fail(f"DIMENSIONS {self.dims} must be positive")
            n = int(np.prod(self.dims, dtype=object))
            if n > self.size:
                self.fail(f"DIMENSIONS {self.dims} claims {n} points, more than the file's {self.size} bytes can hold")
        elif kw in (b"ORIGIN", b"SPACING", b"ASPECT_RATIO"):
            self.finite(kw.decode(), args)
        elif kw == b"POINTS":
            n = self.counts(args, 1, "POINTS")[0]
            self.need(3 * n, args[1] if len(args) > 1 else b"", left, f"POINTS {n}")
            if self.dataset == b"STRUCTURED_GRID":
                self.agree("POINTS", n, None if self.dims is None else int(np.prod(self.dims, dtype=object)),
                           "DIMENSIONS")
            self.points = n
        elif kw in (b"X_COORDINATES", b"Y_COORDINATES", b"Z_COORDINATES"):
            n = self.counts(args, 1, kw.decode())[0]
            self.need(n, args[1] if len(args) > 1 else b"", left, f"{kw.decode()} {n}")
            self.agree(kw.decode(), n, None if self.dims is None else self.dims[b"XYZ".index(kw[:1])], "DIMENSIONS")
        elif kw in _CELL_LISTS:
            self.cell_list(kw, args, left)
        elif kw in (b"OFFSETS", b"CONNECTIVITY"):
            n = self.pending.pop(kw, 0)
            self.need(n, args[0] if args else b"", left, f"{kw.decode()} of {n} values")
        elif kw == b"CELL_TYPES":
            n = self.counts(args, 1, "CELL_TYPES")[0]
            self.need(n, b"int", left, f"CELL_TYPES {n}")
            self.agree("CELL_TYPES", n, self.cells, "CELLS")
        elif kw in (b"POINT_DATA", b"CELL_DATA"):
            n = self.counts(args, 1, kw.decode())[0]
            self.need(n, b"unsigned_char", left, f"{kw.decode()} {n}")
            self.attribute_count(kw, n)
        elif kw == b"FIELD":
            return self.field(args, end, left)
        else:
            self.attribute_line(kw, args, left)
        return end

    def finite(self, what: str, args: list[bytes]) -> None:
        try:
            values = [float(a) for a in args[:3]]
        except ValueError:
            values = []
        if len(values) != 3 or not all(np.isfinite(values)):
            self.fail(f"{what} must be three finite numbers (it is {describe_bytes(b' '.join(args))})")

    def cell_list(self, kw: bytes, args: list[bytes], left: int) -> None:
        n, size = self.counts(args, 2, kw.decode())
        if self.version >= 5:  # n offsets (one more than the cells) and size connectivity ids follow
            self.pending = {b"OFFSETS": n, b"CONNECTIVITY": size}
            cells = max(n - 1, 0)
        else:
            if size < n:
                self.fail(f"{kw.decode()} {n} {size}: {size} values cannot describe {n} cells")
            self.need(size, b"int", left, f"{kw.decode()} {n} {size}")
            cells = n
        if kw == b"CELLS":
            self.cells = cells
        else:
            self.cell_lists += cells
            self.cells = self.cell_lists

    def attribute_count(self, kw: bytes, n: int) -> None:
        if kw == b"POINT_DATA":
            expected = int(np.prod(self.dims, dtype=object)) if self.dims is not None else self.points
            self.agree("POINT_DATA", n, expected, "DIMENSIONS" if self.dims is not None else "POINTS")
        else:
            structured = self.dataset in (b"STRUCTURED_POINTS", b"STRUCTURED_GRID", b"RECTILINEAR_GRID")
            self.agree("CELL_DATA", n, self.structured_cells() if structured else self.cells,
                       "DIMENSIONS" if structured else "the cell lists")
        self.attribute = (kw, n)

    def attribute_line(self, kw: bytes, args: list[bytes], left: int) -> None:
        """SCALARS, VECTORS, LOOKUP_TABLE ...: their values against the current POINT_DATA / CELL_DATA count."""
        n = self.attribute[1] if self.attribute else 0
        if kw == b"SCALARS":
            components = self.counts(args[2:], 1, "SCALARS components")[0] if len(args) > 2 else 1
            if not 1 <= components <= 4:
                self.fail(f"SCALARS with {components} components (VTK takes 1 to 4)")
            self.need(n * components, args[1] if len(args) > 1 else b"", left, f"SCALARS of {n} x {components}")
        elif kw == b"COLOR_SCALARS":
            components = self.counts(args[1:], 1, "COLOR_SCALARS components")[0]
            self.need(n * components, b"unsigned_char", left, f"COLOR_SCALARS of {n} x {components}")
        elif kw == b"LOOKUP_TABLE" and len(args) > 1:
            entries = self.counts(args[1:], 1, "LOOKUP_TABLE size")[0]
            self.need(4 * entries, b"unsigned_char", left, f"LOOKUP_TABLE of {entries} colors")
        elif kw == b"TEXTURE_COORDINATES":
            dim = self.counts(args[1:], 1, "TEXTURE_COORDINATES dimension")[0]
            if not 1 <= dim <= 3:
                self.fail(f"TEXTURE_COORDINATES of dimension {dim} (VTK takes 1 to 3)")
            self.need(n * dim, args[2] if len(args) > 2 else b"", left, f"TEXTURE_COORDINATES of {n} x {dim}")
        elif kw in _COMPONENTS:
            self.need(n * _COMPONENTS[kw], args[1] if len(args) > 1 else b"", left, f"{kw.decode()} of {n}")

    # -- FIELD blocks -----------------------------------------------------------------------------------------------
    def field(self, args: list[bytes], pos: int, left: int) -> int:
        """Walk a ``FIELD name n`` block from ``pos``; returns where it ends (or where the walk had to stop)."""
        n = self.counts(args[1:], 1, "FIELD array count")[0]
        if 8 * n > left:  # the shortest array is a line like "a 0 0 int"
            self.fail(f"FIELD announces {n} arrays, more than the {left} bytes after it can hold")
        for k in range(n):
            where = f"FIELD array {k + 1} of {n}"
            pos = self.skip_space(pos)
            if pos >= self.size:
                self.fail(f"file ends after {k} of the {n} arrays its FIELD announces")
            end = self.mm.find(b"\n", pos)
            end = self.size if end < 0 else end + 1
            head = self.mm[pos:end].split()
            if head == [b"NULL_ARRAY"]:
                pos = end - 1
                continue
            if len(head) < 4 or not (head[1].isdigit() and head[2].isdigit()):
                self.fail(f"{where}: its line is {describe_bytes(bytes(self.mm[pos:min(end, pos + 200)]))}, not "
                          "'name components tuples type'")
            values = int(head[1]) * int(head[2])
            self.need(values, head[3], self.size - end, where)
            pos = self.skip_metadata(self.skip_values(end, values, head[3]))
        return pos

    def skip_space(self, pos: int) -> int:
        while pos < self.size and _WHITESPACE[self.mm[pos]]:
            pos += 1
        return pos

    def skip_values(self, pos: int, values: int, dtype: bytes) -> int:
        """The position after ``values`` values of ``dtype`` starting at ``pos`` (the first byte of the data)."""
        name = dtype.decode("ascii", "replace").lower()
        size = _TYPE_BYTES.get(name, 1)
        if name in _STRINGS:
            end = self.skip_strings(pos, values)
        elif self.binary:
            assert size is not None  # None only for the string types
            end = pos + (-(-values // 8) if size == 0 else values * size)
        else:
            end = skip_tokens(self.mm, pos, values)
        if end is None or end > self.size:
            self.fail(f"file ends inside the {values} values of an array of a FIELD block")
        return end

    def skip_strings(self, pos: int, count: int) -> int | None:
        """Skip ``count`` strings: one per line in ASCII files; in binary files each starts with its length, in
        1, 2, 4 or 8 big-endian bytes whose top two bits say which (11, 10, 01, 00)."""
        for _ in range(count):
            if pos >= self.size:
                return None
            if not self.binary:
                end = self.mm.find(b"\n", pos)
                pos = self.size if end < 0 else end + 1
                continue
            width = {3: 1, 2: 2, 1: 4, 0: 8}[self.mm[pos] >> 6]
            length = int.from_bytes(self.mm[pos:pos + width], "big") & ((1 << (8 * width - 2)) - 1)
            pos += width + length
        return pos

    def skip_metadata(self, pos: int) -> int:
        """Skip an array's ``METADATA`` block (its lines up to an empty line), if one follows."""
        start = self.skip_space(pos)
        if self.mm[start:start + 8].upper() != b"METADATA":
            return pos
        blank = re.compile(rb"\n[ \t\r]*\n").search(self.mm, start)
        return self.size if blank is None else blank.end() - 1


def skip_tokens(mm, pos: int, count: int) -> int | None:
    """The position just after the ``count``-th whitespace-separated token from ``pos``; None if the data ends
    first. Counted a few megabytes at a time with NumPy, so long ASCII arrays are skipped quickly."""
    size = len(mm)
    previous_space = True
    while count > 0:
        block = np.frombuffer(mm[pos:pos + _CHUNK], np.uint8)
        if block.size == 0:
            return None
        space = _WHITESPACE[block]
        starts = np.flatnonzero(~space & np.concatenate(([previous_space], space[:-1])))
        if len(starts) >= count:
            pos += int(starts[count - 1])
            while pos < size and not _WHITESPACE[mm[pos]]:
                pos += 1
            return pos
        count -= len(starts)
        previous_space = bool(space[-1])
        pos += block.size
    return pos


def check_legacy_file(path: PathLike) -> None:
    """Refuse a legacy .vtk file whose header or counts are wrong anywhere in the file (see the module docstring)."""
    with open_file(path) as fh:
        head = fh.read(len(MAGIC))
        if head != MAGIC:
            raise ReadError(path, f"not a VTK legacy file: starts with {describe_bytes(head)}, not "
                                  "'# vtk DataFile Version'")
        with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as mm:
            _check_mapped(path, mm)


def _check_mapped(path: PathLike, mm: mmap.mmap) -> None:
    first = mm.find(b"\n")
    title = mm.find(b"\n", first + 1) if first >= 0 else -1
    if title < 0:
        raise ReadError(path, "VTK legacy file ends in its first two lines (version and title)")
    match = re.match(rb"\s*([0-9]+(?:\.[0-9]*)?)", mm[len(MAGIC):first])
    version = float(match.group(1)) if match else 0.0
    fmt = re.match(rb"\s*(\S+)", mm[title + 1:title + 256])
    kind = fmt.group(1).upper() if fmt else b""
    if kind not in (b"ASCII", b"BINARY"):
        raise ReadError(path, f"VTK legacy format line is {describe_bytes(kind)}, not ASCII or BINARY")
    scan = _Scan(path, mm, kind == b"BINARY", version)
    resume = title
    for m in _LINE.finditer(mm, title):
        if m.start() < resume:
            continue  # inside a FIELD block already walked
        resume = scan.line(m.group(1), m.group(2).split(), m.end())
