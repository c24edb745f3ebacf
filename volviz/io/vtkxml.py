"""Checks of a VTK XML file (.vti .vtu .vts .vtr .vtp) before VTK's reader sees it.

VTK's XML readers trust the markup: a ``NumberOfTuples`` of 2^31-1, an ``Extent`` with swapped bounds, a flipped
``byte_order`` or a compressed-data header announcing 0xFFFFFFFF blocks make them allocate absurd arrays, read past
their buffers and crash. Here the markup (everything before ``<AppendedData``, memory-mapped, never copied whole) is
walked tag by tag and every number is held against the file and against the others:

- ``<VTKFile>``: the data set type the extension expects, ``byte_order``, ``header_type`` and ``compressor`` from
  the values VTK knows;
- the data set element: ``WholeExtent`` with ordered bounds, ``Origin``, ``Spacing`` and ``Direction`` finite;
- each ``<Piece>``: its ``Extent`` ordered and inside the whole extent, or its ``NumberOfPoints``, ``NumberOfCells``,
  ``NumberOfVerts`` ... counts, none more than the file could hold;
- each ``<DataArray>``: a known ``format``, ``NumberOfComponents`` at least 1, ``NumberOfTuples`` equal to what its
  section needs (the piece's points for point data and points, its cells for cell data and cell types, the extent
  along an axis for rectilinear coordinates), and its data: ASCII values that fit the text, and for binary data
  (inline base64 or appended, raw or base64) the header VTK reads first -- the byte count, or the compressed blocks'
  count and sizes -- inside the file, consistent with the array's size and with what the compressor can expand to;
  appended offsets inside the file.
"""
from __future__ import annotations

import base64
import binascii
import mmap
import re
from dataclasses import dataclass
from typing import NoReturn, overload

import numpy as np

from volviz.io._checks import describe_bytes, open_file
from volviz.io.errors import PathLike, ReadError, bytes_and_size

TYPE_BYTES = {"Int8": 1, "UInt8": 1, "Char": 1, "Int16": 2, "UInt16": 2, "Int32": 4, "UInt32": 4, "Int64": 8,
              "UInt64": 8, "Float32": 4, "Float64": 8, "Bit": 0, "String": None}
BYTE_ORDERS = {"LittleEndian": "<", "BigEndian": ">"}
HEADER_TYPES = {"UInt32": 4, "UInt64": 8}
# how far each compressor can expand data at most (deflate ~1032:1, LZ4 ~255:1; LZMA far more, bounded loosely)
COMPRESSORS = {"vtkZLibDataCompressor": 1100, "vtkLZ4DataCompressor": 300, "vtkLZMADataCompressor": 100_000}
STRUCTURED = ("ImageData", "RectilinearGrid", "StructuredGrid")
POLY_COUNTS = ("NumberOfVerts", "NumberOfLines", "NumberOfStrips", "NumberOfPolys")
_TAG = re.compile(rb"<(/?)([A-Za-z_][\w.:-]*)((?:[^>\"']|\"[^\"]*\"|'[^']*')*?)(/?)>")
_ATTR = re.compile(rb"([A-Za-z_][\w.:-]*)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
_SPACE = b" \t\r\n"


@dataclass
class _Piece:
    points: int
    cells: int
    dims: tuple[int, int, int] | None = None
    verts_lines_strips_polys: dict[str, int] | None = None


class _Check:
    def __init__(self, path: PathLike, mm: mmap.mmap, expected_type: str) -> None:
        self.path, self.mm, self.size, self.expected = path, mm, len(mm), expected_type
        self.order, self.header, self.ratio = "<", 4, 1
        self.whole: list[int] | None = None
        self.piece: _Piece | None = None
        self.piece_extents: list[list[int]] = []
        self.section = ""
        self.coordinate = 0
        self.appended_start: int | None = None
        self.appended_base64 = False
        self.budget = self.size

    def fail(self, problem: str) -> NoReturn:
        raise ReadError(self.path, f"VTK XML {problem}")

    # -- attribute values -------------------------------------------------------------------------------------------
    def ints(self, attrs: dict[str, str], key: str, n: int, where: str) -> list[int] | None:
        if key not in attrs:
            return None
        tokens = attrs[key].split()
        if len(tokens) != n or not all(re.fullmatch(r"[+-]?\d+", t) for t in tokens):
            self.fail(f"{where} {key} is {describe_bytes(attrs[key])}, not {n} integer{'s' if n > 1 else ''}")
        return [int(t) for t in tokens]

    @overload
    def count(self, attrs: dict[str, str], key: str, where: str, default: int) -> int: ...

    @overload
    def count(self, attrs: dict[str, str], key: str, where: str, default: None = None) -> int | None: ...

    def count(self, attrs: dict[str, str], key: str, where: str, default: int | None = None) -> int | None:
        values = self.ints(attrs, key, 1, where)
        if values is None:
            return default
        if values[0] < 0:
            self.fail(f"{where} {key} is {values[0]}, a negative count")
        if values[0] > self.budget:
            self.fail(f"{where} {key} is {values[0]}, more than the file's {bytes_and_size(self.size)}"
                      f" can hold")
        return values[0]

    def finite(self, attrs: dict[str, str], key: str, n: int, where: str) -> None:
        if key not in attrs:
            return
        try:
            values = [float(t) for t in attrs[key].split()]
        except ValueError:
            values = []
        if len(values) != n or not all(np.isfinite(values)):
            self.fail(f"{where} {key} must be {n} finite numbers")

    def extent(self, attrs: dict[str, str], key: str, where: str) -> list[int] | None:
        e = self.ints(attrs, key, 6, where)
        if e is None:
            return None
        if any(e[2 * i] > e[2 * i + 1] for i in range(3)):
            self.fail(f"{where} {key} {e} has a lower bound above its upper bound")
        points = int(np.prod([e[2 * i + 1] - e[2 * i] + 1 for i in range(3)], dtype=object))
        if points > self.budget:
            self.fail(f"{where} {key} {e} claims {points} points, more than the file's {bytes_and_size(self.size)}"
                      f" can hold")
        return e

    # -- elements ---------------------------------------------------------------------------------------------------
    def vtkfile(self, attrs: dict[str, str]) -> None:
        kind = attrs.get("type", "")
        if kind != self.expected:
            self.fail(f"file holds {kind or 'no data set type'}, but its extension expects {self.expected}")
        for key, known in (("byte_order", BYTE_ORDERS), ("header_type", HEADER_TYPES), ("compressor", COMPRESSORS)):
            if key in attrs and attrs[key] not in known:
                self.fail(f"{key} is not one of {', '.join(known)}")
        self.order = BYTE_ORDERS[attrs.get("byte_order", "LittleEndian")]
        self.header = HEADER_TYPES[attrs.get("header_type", "UInt32")]
        self.ratio = COMPRESSORS.get(attrs.get("compressor", ""), 1)
        self.budget = self.size * self.ratio

    def dataset(self, attrs: dict[str, str]) -> None:
        where = self.expected
        if self.expected in STRUCTURED:
            self.whole = self.extent(attrs, "WholeExtent", where)
            if self.whole is None:
                self.fail(f"{where} has no WholeExtent")
        self.finite(attrs, "Origin", 3, where)
        self.finite(attrs, "Spacing", 3, where)
        self.finite(attrs, "Direction", 9, where)

    def start_piece(self, attrs: dict[str, str]) -> None:
        if self.expected in STRUCTURED:
            e = self.extent(attrs, "Extent", "Piece")
            if e is None:
                self.fail("Piece has no Extent")
            w = self.whole
            if w is None:
                self.fail(f"Piece comes before the {self.expected} element that gives its WholeExtent")
            if any(e[2 * i] < w[2 * i] or e[2 * i + 1] > w[2 * i + 1] for i in range(3)):
                self.fail(f"Piece Extent {e} reaches outside the WholeExtent {w}")
            self.piece_extents.append(e)
            dims = tuple(e[2 * i + 1] - e[2 * i] + 1 for i in range(3))
            cells = int(np.prod([max(d - 1, 1) for d in dims], dtype=object))
            self.piece = _Piece(int(np.prod(dims, dtype=object)), cells, dims)  # type: ignore[arg-type]
            return
        points = self.count(attrs, "NumberOfPoints", "Piece", 0)
        if self.expected == "PolyData":
            lists = {k: self.count(attrs, k, "Piece", 0) for k in POLY_COUNTS}
            self.piece = _Piece(points, sum(lists.values()), verts_lines_strips_polys=lists)
        else:
            self.piece = _Piece(points, self.count(attrs, "NumberOfCells", "Piece", 0))

    def expected_tuples(self, name: str) -> int | None:
        """How many tuples an array in the current section must have (None: any number)."""
        p, section = self.piece, self.section
        if p is None:
            return None
        if section in ("PointData", "Points"):
            return p.points
        if section == "CellData":
            return p.cells
        if section == "Coordinates" and p.dims is not None and self.coordinate < 3:
            return p.dims[self.coordinate]
        if section == "Cells" and name == "types":
            return p.cells
        if section in ("Verts", "Lines", "Strips", "Polys") and name == "offsets" and p.verts_lines_strips_polys:
            return p.verts_lines_strips_polys[f"NumberOf{section}"]
        return None

    def data_array(self, attrs: dict[str, str], start: int, self_closing: bool) -> None:
        name = attrs.get("Name", "")
        where = f"DataArray {len(name) < 60 and name.isprintable() and repr(name) or '(unnamed)'} in {self.section}"
        fmt = attrs.get("format", "ascii")
        if fmt not in ("ascii", "binary", "appended"):
            self.fail(f"{where}: format is {describe_bytes(fmt)}, not ascii, binary or appended")
        components = self.count(attrs, "NumberOfComponents", where, 1)
        if components < 1:
            self.fail(f"{where}: NumberOfComponents is 0")
        declared = self.count(attrs, "NumberOfTuples", where)
        expected = self.expected_tuples(name)
        if self.section == "Coordinates":
            self.coordinate += 1
        if expected is not None and declared is not None and declared != expected:
            self.fail(f"{where}: NumberOfTuples is {declared}, but its piece needs {expected}")
        tuples = expected if expected is not None else declared
        size = TYPE_BYTES.get(attrs.get("type", ""))
        nbytes = None
        if tuples is not None and size is not None:
            values = tuples * components
            nbytes = -(-values // 8) if size == 0 else values * size
            if nbytes > self.budget:
                self.fail(f"{where}: {tuples} tuples of {components} need {bytes_and_size(nbytes)}, "
                          f"more than the file's {self.size} bytes can hold")
        if fmt == "appended":
            self.appended(attrs, where, nbytes)
        elif not self_closing:
            self.inline(start, fmt, where, nbytes, None if tuples is None else tuples * components)

    # -- array data -------------------------------------------------------------------------------------------------
    def inline(self, start: int, fmt: str, where: str, nbytes: int | None, values: int | None) -> None:
        end = self.mm.find(b"</DataArray>", start)
        if end < 0:
            self.fail(f"{where} has no closing </DataArray>")
        a, b = self.content(start, end)
        if fmt == "ascii":
            if values is not None and values > 0 and 2 * values - 1 > b - a:
                self.fail(f"{where}: {values} ASCII values cannot fit in its {b - a} characters")
            return
        self.binary_header(a, b, where, nbytes, encoded=True)

    def content(self, start: int, end: int) -> tuple[int, int]:
        """The span of an array's text between ``start`` and ``end``, outside any child element, trimmed."""
        first = self.mm.find(b"<", start, end)
        a, b = (start, end) if first < 0 else (start, first)
        if first >= 0 and not bytes(self.mm[a:b]).strip():
            a = self.mm.rfind(b">", start, end) + 1
        while a < b and self.mm[a] in _SPACE:
            a += 1
        while b > a and self.mm[b - 1] in _SPACE:
            b -= 1
        return a, b

    def appended(self, attrs: dict[str, str], where: str, nbytes: int | None) -> None:
        if self.appended_start is None:
            self.fail(f"{where} is appended, but the file has no <AppendedData> section")
        offset = self.ints(attrs, "offset", 1, where)
        if offset is None or offset[0] < 0:
            self.fail(f"{where} is appended without a valid offset")
        pos = self.appended_start + offset[0]
        if pos >= self.size:
            self.fail(f"{where}: appended offset {offset[0]} points past the end of the file")
        self.binary_header(pos, self.size, where, nbytes, encoded=self.appended_base64)

    def uints(self, pos: int, end: int, count: int, encoded: bool) -> list[int]:
        """``count`` header integers at ``pos`` (raw bytes, or base64 text decoded from its start)."""
        n = count * self.header
        if encoded:
            chars = 4 * -(-n // 3)
            text = re.sub(rb"\s+", b"", bytes(self.mm[pos:min(end, pos + 2 * chars + 64)]))[:chars]
            try:
                raw = base64.b64decode(text, validate=True) if len(text) == chars else b""
            except binascii.Error:
                raw = b""
        else:
            raw = bytes(self.mm[pos:min(end, pos + n)])
        if len(raw) < n:
            return []
        dtype = np.dtype(f"{self.order}u{self.header}")
        return [int(v) for v in np.frombuffer(raw[:n], dtype)]

    def binary_header(self, pos: int, end: int, where: str, nbytes: int | None, encoded: bool) -> None:
        """Check the header VTK reads before binary data: the byte count, or the compressed block table."""
        room = (end - pos) * 3 // 4 if encoded else end - pos
        if self.ratio == 1:
            head = self.uints(pos, end, 1, encoded)
            if not head:
                self.fail(f"{where}: its binary data is cut short before its header")
            total, stored = head[0], head[0] + self.header
        else:
            head = self.uints(pos, end, 3, encoded)
            if not head:
                self.fail(f"{where}: its compressed data is cut short before its header")
            blocks, block, last = head
            table = (3 + blocks) * self.header
            if table > room:
                self.fail(f"{where}: the compressed data header announces {blocks} blocks, more than the "
                          f"{room} bytes of data left can describe")
            sizes = self.uints(pos, end, 3 + blocks, encoded)[3:]
            if len(sizes) != blocks:
                self.fail(f"{where}: the compressed data header of {blocks} blocks is cut short")
            if last > block:
                self.fail(f"{where}: the last compressed block holds {last} bytes, more than the block size {block}")
            total = 0 if blocks == 0 else (blocks - 1) * block + (last or block)
            stored = table + sum(sizes)
            if total > self.ratio * sum(sizes) + 64 * blocks:
                self.fail(f"{where}: {blocks} compressed blocks of {sum(sizes)} bytes cannot expand to the "
                          f"{bytes_and_size(total)} their header claims")
        if stored > room + 3:
            self.fail(f"{where}: its binary data needs {bytes_and_size(stored)}, but only {room} "
                      "bytes remain")
        if nbytes is not None and total != nbytes:
            self.fail(f"{where}: its binary data holds {total} bytes, but its tuples and components need {nbytes}")

    # -- the walk ---------------------------------------------------------------------------------------------------
    def run(self) -> None:
        markup_end = self.mm.find(b"<AppendedData")
        if markup_end >= 0:
            tag = _TAG.match(self.mm, markup_end)
            underscore = self.mm.find(b"_", tag.end()) if tag else -1
            if tag is None or underscore < 0:
                self.fail("AppendedData section without its '_' marker")
            self.appended_start = underscore + 1
            self.appended_base64 = _attrs(tag.group(3)).get("encoding", "raw") == "base64"
        else:
            markup_end = self.size
        seen_root = False
        for m in _TAG.finditer(self.mm, 0, markup_end):
            closing, name, self_closing = m.group(1), m.group(2).decode("ascii", "replace"), m.group(4)
            if closing:
                if name == self.section:
                    self.section = ""
                continue
            attrs = _attrs(m.group(3))
            if name == "VTKFile":
                self.vtkfile(attrs)
                seen_root = True
            elif not seen_root:
                continue
            elif name == self.expected:
                self.dataset(attrs)
            elif name == "Piece":
                self.start_piece(attrs)
            elif name in ("PointData", "CellData", "Points", "Coordinates", "Cells", "Verts", "Lines", "Strips",
                          "Polys", "FieldData"):
                self.section, self.coordinate = ("" if self_closing else name), 0
            elif name == "DataArray":
                self.data_array(attrs, m.end(), bool(self_closing))
        if not seen_root:
            self.fail("file has no <VTKFile> element")
        self.pieces_cover_the_whole_extent()

    def pieces_cover_the_whole_extent(self) -> None:
        """A structured file's pieces fill its WholeExtent (VTK leaves the points no piece covers unset): their
        bounding box is the whole extent and they hold at least its points."""
        if self.expected not in STRUCTURED or self.whole is None or not self.piece_extents:
            return
        w, pieces = self.whole, self.piece_extents
        box = [f(p[k] for p in pieces) for k in range(6) for f in ((min,) if k % 2 == 0 else (max,))]
        points = sum(int(np.prod([p[2 * i + 1] - p[2 * i] + 1 for i in range(3)], dtype=object)) for p in pieces)
        whole = int(np.prod([w[2 * i + 1] - w[2 * i] + 1 for i in range(3)], dtype=object))
        if box != list(w) or points < whole:
            self.fail(f"pieces (extents {pieces}) do not fill the WholeExtent {w}: points outside every piece "
                      "would be made up")


def _attrs(text: bytes) -> dict[str, str]:
    return {k.decode("ascii", "replace"): (v1 if v1 is not None else v2).decode("utf-8", "replace")
            for k, v1, v2 in (m.groups() for m in _ATTR.finditer(text))}


def check_xml_file(path: PathLike, expected_type: str) -> None:
    """Refuse a VTK XML file whose markup, counts or binary headers are inconsistent (see the module docstring)."""
    with open_file(path) as fh:
        head = fh.read(64).lstrip()
        if not (head.startswith(b"<?xml") or head.startswith(b"<VTKFile")):
            raise ReadError(path, f"not a VTK XML file: starts with {describe_bytes(head)}, not '<?xml' or "
                                  "'<VTKFile'")
        with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as mm:
            _Check(path, mm, expected_type).run()
