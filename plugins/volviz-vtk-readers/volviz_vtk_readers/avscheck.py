"""A cheap check of an AVS UCD file's header counts against what the file holds, before VTK's vtkAVSucdReader.

VTK's reader reads an ASCII file cut within its node or cell lines as other values (issue #32: 17 damaged files
accepted). The layout (AVS/Express "UCD file format"; VTK's reader for the binary variant):

- ASCII: after ``#`` comments, ``nodes cells node_values cell_values model_values``; one line per node
  (``id x y z``); one per cell (``id material type n1 ... nk``, k the type's node count); for node (then cell) data
  a line ``components size1 ... sizeN`` (the sizes adding up to the header's value count), one ``label, unit`` line
  per component and one line per node (cell) of ``id`` and its values. Each section is checked line by line; lines
  after the last section, or a last line without its line end (a value that may have lost digits), are a
  ReadWarning.
- binary (first byte 7): six 32-bit counts (nodes, cells, node fields, cell fields, model fields, connectivity
  length), then blocks whose sizes follow from them: the file must be exactly that long in one byte order.
"""
from __future__ import annotations

import struct
import warnings
from pathlib import Path

from volviz.io.errors import PathLike, ReadError, ReadWarning

NODES_PER_CELL = {"pt": 1, "line": 2, "tri": 3, "quad": 4, "tet": 4, "pyr": 5, "prism": 6, "hex": 8}
MAX_ASCII_BYTES = 256 << 20          # larger ASCII files are left to VTK (walking their lines costs seconds)
_HEADER = ("nodes", "cells", "node values", "cell values", "model values")


def binary_size(counts: tuple[int, ...]) -> int:
    """The length VTK's reader expects of a binary file with these six header counts."""
    nodes, cells, node_fields, cell_fields, fields, nlist = counts
    size = 1 + 6 * 4 + 16 * cells + 4 * nlist + 12 * nodes
    size += 2052 + node_fields * (12 + 4 * nodes + 4) if node_fields else 0
    size += 2052 + cell_fields * (12 + 4 * cells + 4) if cell_fields else 0
    return size + (2052 + fields * 20 if fields else 0)


def _check_binary(p: Path) -> None:
    with open(p, "rb") as f:
        head = f.read(25)
    size = p.stat().st_size
    if len(head) < 25:
        raise ReadError(p, f"binary AVS UCD: the file holds {size} bytes, fewer than its 25-byte header")
    orders = [struct.unpack(o + "6i", head[1:25]) for o in "<>"]
    for counts in orders:
        if min(counts) >= 0 and binary_size(counts) == size:
            return
    counts = orders[0]
    names = "nodes, cells, node fields, cell fields, model fields, connectivity length"
    if min(counts) < 0:
        raise ReadError(p, f"binary AVS UCD: the header's counts ({names}) are {list(counts)}; a count cannot be "
                           "negative")
    raise ReadError(p, f"binary AVS UCD: the header's counts ({names}) {list(counts)} need {binary_size(counts)} "
                       f"bytes but the file holds {size}: it is truncated or the header is wrong")


class _Lines:
    def __init__(self, p: Path) -> None:
        self.p = p
        self.lines = [(n, ln.split()) for n, ln in enumerate(p.read_text(encoding="latin-1").splitlines(), 1)
                      if ln.strip() and not ln.lstrip().startswith("#")]
        self.i = 0

    def next(self, what: str) -> tuple[int, list[str]]:
        if self.i >= len(self.lines):
            raise ReadError(self.p, f"ends where {what} should be: the file is truncated or a header count is wrong")
        self.i += 1
        return self.lines[self.i - 1]


def _numbers(tokens: list[str]) -> bool:
    try:
        [float(t) for t in tokens]
    except ValueError:
        return False
    return True


def _check_rows(f: _Lines, count: int, fields: int, what: str, header: str) -> None:
    """``count`` lines of ``fields`` numbers (an id and its values)."""
    for k in range(count):
        number, tokens = f.next(f"{what} {k + 1} of {count}")
        if len(tokens) != fields or not _numbers(tokens):
            raise ReadError(f.p, f"line {number} ({' '.join(tokens)[:40]!r}) is not {what} {k + 1} of {count} "
                                 f"({fields} numbers) that {header}")


def _check_data(f: _Lines, values: int, rows: int, what: str) -> None:
    """A data section: the components line, their labels, one line per node or cell."""
    number, tokens = f.next(f"the {what} data's components line")
    if not tokens or not all(t.isdigit() for t in tokens) or int(tokens[0]) != len(tokens) - 1:
        raise ReadError(f.p, f"line {number} ({' '.join(tokens)[:40]!r}) is not the {what} data's components line "
                             "(a count and that many sizes)")
    sizes = [int(t) for t in tokens[1:]]
    if sum(sizes) != values:
        raise ReadError(f.p, f"line {number}: the {what} data's component sizes add up to {sum(sizes)} but the "
                             f"header says {values} {what} values")
    for k in range(len(sizes)):
        f.next(f"the label of {what} component {k + 1}")
    _check_rows(f, rows, 1 + values, f"{what} data line", f"the header's {rows} {what}s need")


def check_avs_ucd(path: PathLike) -> None:
    """ReadError naming the file and the count when the AVS UCD file does not hold what its header says; a
    ReadWarning for lines after the last section."""
    p = Path(path)
    with open(p, "rb") as raw:
        if raw.read(1) == b"\x07":
            return _check_binary(p)
    if p.stat().st_size > MAX_ASCII_BYTES:
        return None
    f = _Lines(p)
    number, tokens = f.next("the header line")
    if len(tokens) != 5 or not all(t.lstrip("-").isdigit() for t in tokens):
        raise ReadError(p, f"line {number} ({' '.join(tokens)[:40]!r}) is not the header line (five counts: "
                           f"{', '.join(_HEADER)})")
    counts = dict(zip(_HEADER, map(int, tokens)))
    for name, value in counts.items():
        if value < 0:
            raise ReadError(p, f"the header's {name} count is {value}; a count cannot be negative")
    nodes, cells = counts["nodes"], counts["cells"]
    _check_rows(f, nodes, 4, "node", f"the header's {nodes} nodes need")
    for k in range(cells):
        number, tokens = f.next(f"cell {k + 1} of {cells}")
        needed = NODES_PER_CELL.get(tokens[2].lower()) if len(tokens) > 2 else None
        if needed is None or len(tokens) != 3 + needed or not _numbers(tokens[:2] + tokens[3:]):
            raise ReadError(p, f"line {number} ({' '.join(tokens)[:40]!r}) is not cell {k + 1} of {cells} (id, "
                               "material, type and its nodes) that the header's count needs")
    for what, rows in (("node", nodes), ("cell", cells)):
        if counts[f"{what} values"]:
            _check_data(f, counts[f"{what} values"], rows, what)
    with open(p, "rb") as end:
        end.seek(-1, 2)
        if end.read(1) not in b"\r\n":
            warnings.warn(f"{p}: the file does not end with a line end: line {f.lines[-1][0]}, its last, may be cut "
                          "short (a value of fewer digits)", ReadWarning, stacklevel=3)
    if f.i < len(f.lines) and not counts["model values"]:
        warnings.warn(f"{p}: {len(f.lines) - f.i} lines after the sections the header counts (from line "
                      f"{f.lines[f.i][0]}) are not read", ReadWarning, stacklevel=3)
    return None
