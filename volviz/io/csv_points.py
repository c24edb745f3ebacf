"""Point tables (``.csv``, ``.tsv``; ``.xyz``, ``.pts``, ``.txt`` known by content, ``is_point_text``): a header
row naming the columns, then a row of numbers per point -- what ParaView opens with its CSV reader and "Table To
Points", and what a logger, a particle tracker or a spreadsheet writes. Text point clouds may have no header (the
first three columns are then x, y, z, the others ``column 4`` ... or red, green, blue, as scanners and surveys write
them; a Leica .pts point count before the rows is skipped); .csv and .tsv tables need theirs. The columns named x, y
and z (any case; ParaView's own exports name them ``Points:0``, ``Points:1``, ``Points:2``) place the points, or the
columns the options ``x=``, ``y=``, ``z=`` name; a table without a z column lies in the z = 0 plane. Every other
numeric column is an array on the points; columns of text are left out (named in a warning). Comma, semicolon, tab
or blank separated; ``#`` starts a comment. Rows whose coordinates are missing, and rows of another number of
fields than the header's (without a header: than most rows hold, the first row's count being no better than any
other's), are left out with one warning naming them by line. The points are vertices of an ``UnstructuredMesh``,
drawn as points coloured by an array.
"""
from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, check_finite
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.model import UnstructuredMesh

#: the largest table read (bytes of text)
MAX_BYTES = 2 << 30
#: header names taken for each coordinate, in lower case without blanks
COORDINATE_NAMES = ({"x", "points:0", "coordsx", "coordinatex", "posx", "positionx"},
                    {"y", "points:1", "coordsy", "coordinatey", "posy", "positiony"},
                    {"z", "points:2", "coordsz", "coordinatez", "posz", "positionz"})
SAMPLE_ROWS = 200
HEAD_SNIFF = 4096  # the bytes the registry gives a sniffer
TABLE_ROWS = 8     # rows of one width that make a table even beside a large minority of odd ones (is_point_text)


def _separator(line: str) -> str | None:
    """The column separator of a header line: tab, semicolon, comma, else blanks (None)."""
    for sep in ("\t", ";", ","):
        if sep in line:
            return sep
    return None


def _fields(line: str, sep: str | None) -> list[str]:
    return [f.strip().strip('"').strip("'").strip() for f in (line.split(sep) if sep else line.split())]


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _key(name: str) -> str:
    return re.sub(r"[\s_]+", "", name.lower())


def _coordinate_columns(p: Path, names: list[str], asked: tuple[str | None, ...]) -> list[int | None]:
    """The columns of x, y, z (None: no z, the plane z = 0); a ReadError naming the columns when x or y is missing."""
    out: list[int | None] = []
    for axis, (wanted, known) in enumerate(zip(asked, COORDINATE_NAMES)):
        label = "xyz"[axis]
        if wanted is not None:
            if wanted not in names:
                raise ReadError(p, f"has no column {wanted!r} (asked for as {label}); its columns are: "
                                   + ", ".join(names))
            out.append(names.index(wanted))
            continue
        found = [i for i, n in enumerate(names) if _key(n) in known]
        if not found and axis < 2:
            raise ReadError(p, f"has no column named {label} for the points' {label} coordinate; its columns are: "
                               + ", ".join(names[:30]) + (" ..." if len(names) > 30 else ""),
                            "name the coordinate columns with the options x=, y= (and z=)")
        out.append(found[0] if found else None)
    return out


def _numbers(p: Path, sep: str | None, skip: int, columns: list[int], n_fields: int,
             headerless: bool = False) -> np.ndarray:
    """The ``columns`` of the rows after the first ``skip`` lines as float64 (rows, columns): NumPy's fast parser
    when every row is complete (about 10x genfromtxt's speed: a million rows in 0.2 s; with every column numeric it
    also refuses a row of another length), else ``_complete_rows`` and genfromtxt, which reads missing values as NaN."""
    if len(columns) < n_fields:                 # columns of text: the fast parser would not see a row's length
        return _parse(p, sep, _complete_rows(p, sep, skip, n_fields, headerless), columns)
    try:
        return np.loadtxt(p, delimiter=sep, skiprows=skip, comments="#", dtype=np.float64, ndmin=2,
                          encoding="utf-8")
    except (ValueError, UnicodeDecodeError):
        return _parse(p, sep, _complete_rows(p, sep, skip, n_fields, headerless), columns)


def _parse(p: Path, sep: str | None, rows: list[str], columns: list[int]) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # genfromtxt's per-row conversion warnings
        try:
            return np.genfromtxt(rows, delimiter=sep, usecols=columns, comments="#", dtype=np.float64,
                                 ndmin=2, encoding="utf-8")
        except (ValueError, UnicodeDecodeError) as exc:
            raise ReadError(p, f"has rows that cannot be read as numbers ({str(exc)[:200]})") from None


#: odd rows a warning names by line
NAMED_ROWS = 10


def _complete_rows(p: Path, sep: str | None, skip: int, n_fields: int, headerless: bool = False) -> list[str]:
    """The rows after the first ``skip`` lines that hold the ``n_fields`` fields the header names (or, without a
    header, most rows hold); the others (a row cut short by a truncated file, a decimal point turned into a comma)
    are left out with one ReadWarning naming them by line (``NAMED_ROWS`` at most): before, genfromtxt dropped them
    without a word (issue #32)."""
    with open(p, encoding="utf-8", errors="replace") as f:
        lines = f.read().splitlines()[skip:]
    good: list[str] = []
    bad: list[tuple[int, int]] = []
    for number, line in enumerate(lines, start=skip + 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        fields = _fields(line.split("#", 1)[0], sep)
        count = len(fields) - (len(fields) == n_fields + 1 and not fields[-1])   # a separator ending the row
        if count == n_fields:
            good.append(line)
        else:
            bad.append((number, count))
    if bad:
        named = ", ".join(f"line {number} holds {count}" for number, count in bad[:NAMED_ROWS])
        more = f", {len(bad) - NAMED_ROWS:,} more" if len(bad) > NAMED_ROWS else ""
        whose = "most of its rows hold" if headerless else "its header names"
        warnings.warn(f"{p}: {len(bad):,} of {len(good) + len(bad):,} rows do not hold the {n_fields} fields "
                      f"{whose} ({named}{more}) and are left out", ReadWarning, stacklevel=4)
    return good


def _rows(lines: list[str]) -> list[str]:
    return [line for line in lines if line.strip() and not line.lstrip().startswith("#")]


def _count_line(lines: list[str], at: int) -> int:
    """1 when the row at ``at`` is a lone point count before rows of 3 or more numbers (Leica .pts), else 0."""
    rest = _rows(lines[at + 1:at + 3])
    row = lines[at].split()
    if len(row) == 1 and row[0].isdigit() and rest:
        following = _fields(rest[0], _separator(rest[0]))
        return int(len(following) >= 3 and all(_number(f) for f in following))
    return 0


def _headerless_width(p: Path, lines: list[str], at: int, sep: str | None) -> int:
    """The number of fields of a table without a header row: the one most of its first ``SAMPLE_ROWS`` rows hold
    (the first row's on a tie), so a damaged row, the first one too, is the odd one left out, not the other 79 of 80
    (issue #32); ReadError when no count is shared by half of them."""
    counts = [len(_fields(line, sep)) for line in _rows(lines[at:at + SAMPLE_ROWS])]
    tally = {n: counts.count(n) for n in counts}
    width = max(tally, key=lambda n: (tally[n], n == counts[0]))
    if 2 * tally[width] < len(counts):
        shown = ", ".join(f"{n} in {k}" for n, k in sorted(tally.items())[:8])
        raise ReadError(p, f"its rows disagree in their number of fields, none shared by half of the first "
                           f"{len(counts)} ({shown}): not a table of points")
    return width


def _headerless_names(lines: list[str], at: int, sep: str | None, n: int) -> list[str]:
    """Names for the ``n`` columns of a table without a header row: x, y, z, then ``column 4`` ...; the last three
    extra columns are red, green, blue when they hold whole numbers 0 to 255 in every sampled row of ``n`` fields
    (scanners' x y z r g b and x y z intensity r g b), a lone column before them ``intensity``."""
    names = ["x", "y", "z"] + [f"column {i}" for i in range(4, n + 1)]
    sample = [row for row in (_fields(line, sep) for line in _rows(lines[at:at + SAMPLE_ROWS])) if len(row) == n]
    if n >= 6 and sample:
        try:
            colors = np.array([[float(v) for v in row[-3:]] for row in sample])
        except ValueError:
            return names
        if np.all(colors == np.round(colors)) and colors.min() >= 0 and colors.max() <= 255:
            names[-3:] = ["red", "green", "blue"]
            if n == 7:
                names[3] = "intensity"
    return names


def is_point_text(head: bytes) -> bool:
    """Text whose first rows (after ``#`` comments and a lone point count) hold numbers, the same number of them
    (3 or more) in at least three rows of four, or in more than half of them when that is ``TABLE_ROWS`` rows or
    more: a header-less point table (.xyz, .pts, .txt), or one whose header row names x and y columns. A minority of
    damaged rows (a first row with a flipped bit, a field lost, a third of the rows with a field more) leaves it a
    table, so the table's reader names them, not the reader of another format sharing the name (issue #32: a .xyz
    with a third of its rows odd went to AVS UCD or PLOT3D). A few rows need three of four (an AVS UCD header line
    and two nodes is not a table); a last row without its line end, cut, is left out of the sample (a table cut in
    its third row was refused as PLOT3D); a binary file's "rows" are not numbers."""
    lines = head.decode("utf-8", errors="replace").splitlines()
    cut = len(head) >= HEAD_SNIFF or (len(lines) > 1 and not head.endswith((b"\n", b"\r")))
    rows = _rows(lines[:-1] if cut else lines)[:20]  # the last line may be cut (the sample's end, or the file's)
    if len(rows) > 1 and _count_line(rows, 0):
        rows = rows[1:]
    if not rows:
        return False
    sep = _separator(rows[min(1, len(rows) - 1)])   # the first row may be the damaged one
    keys = {_key(f) for f in _fields(rows[0], sep)}
    if keys & COORDINATE_NAMES[0] and keys & COORDINATE_NAMES[1] and len(rows) > 1:
        rows = rows[1:]
    shapes = [len(f) if all(_number(v) for v in f) and "\0" not in row else 0
              for row, f in ((row, _fields(row, sep)) for row in rows)]
    width = max(set(shapes), key=shapes.count)
    n = shapes.count(width)
    return width >= 3 and (4 * n >= 3 * len(shapes) or (2 * n > len(shapes) and n >= TABLE_ROWS))


def read_csv_points(path: PathLike, x: str | None = None, y: str | None = None, z: str | None = None,
                    allow_nonfinite: bool = True) -> UnstructuredMesh:
    """The table's rows as points with the other numeric columns as point arrays (see the module docstring); a
    .csv / .tsv table needs its header row (ParaView's CSV reader takes the first row for names)."""
    return _read_points(path, (x, y, z), allow_nonfinite, headerless=False)


def read_text_points(path: PathLike, x: str | None = None, y: str | None = None, z: str | None = None,
                     allow_nonfinite: bool = True) -> UnstructuredMesh:
    """A text point cloud (.xyz, .pts, .txt, or known by content): like ``read_csv_points``, with or without a
    header row."""
    return _read_points(path, (x, y, z), allow_nonfinite, headerless=True)


def _read_points(path: PathLike, asked: tuple[str | None, str | None, str | None], allow_nonfinite: bool,
                 headerless: bool) -> UnstructuredMesh:
    p = check_file(path)
    if p.stat().st_size > MAX_BYTES:
        raise ReadError(p, f"is a table of {p.stat().st_size / 1e9:.1f} GB; volviz reads point tables of at most "
                           f"{MAX_BYTES / 1e9:.1f} GB", "convert it to a binary format (VTK .vtp, HDF5)")
    with open(p, "rb") as f:
        head = f.read(1 << 16)
    if b"\0" in head:
        raise ReadError(p, "is not a text table (it holds zero bytes)")
    lines = head.decode("utf-8", errors="replace").splitlines()
    header_at = next((i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")), None)
    if header_at is None:
        raise ReadError(p, "holds no rows")
    header_at += _count_line(lines, header_at)
    sep = _separator(lines[header_at])
    names = _fields(lines[header_at], sep)
    skip = header_at + 1
    bare = all(_number(n) for n in names)
    if bare:
        width = _headerless_width(p, lines, header_at, sep) if headerless else len(names)
        if not headerless or width < 3:
            raise ReadError(p, "has no header row naming its columns (its first row is numbers" + (
                f", {width} of them in most rows, not the 3 or more of x y z columns)" if headerless else ")"),
                "add a first row naming the columns, with x, y and z for the coordinates")
        names, skip = _headerless_names(lines, header_at, sep, width), header_at
    if len(set(names)) != len(names) or any(not n for n in names):
        raise ReadError(p, "has empty or repeated column names in its header row: " + ", ".join(names[:30]))
    columns = _coordinate_columns(p, names, asked)
    sample = [_fields(line, sep) for line in lines[skip:skip + SAMPLE_ROWS]
              if line.strip() and not line.lstrip().startswith("#")]
    if not sample:
        raise ReadError(p, "has a header row but no rows of values")
    full = [row for row in sample if len(row) == len(names)] or sample  # a row cut short does not make text
    numeric = [i for i in range(len(names)) if all(i < len(row) and (_number(row[i]) or not row[i]) for row in full)]
    for axis, col in enumerate(columns):
        if col is not None and col not in numeric:
            raise ReadError(p, f"its {'xyz'[axis]} column {names[col]!r} holds text, not numbers")
    text = [names[i] for i in range(len(names)) if i not in numeric]
    table = _numbers(p, sep, skip, numeric, len(names), bare)
    if table.size == 0:
        raise ReadError(p, "has no rows of numbers under its header")
    at = {col: k for k, col in enumerate(numeric)}
    coords = [table[:, at[c]] if c is not None else np.zeros(len(table)) for c in columns]
    points = np.stack(coords, axis=1)
    placed = np.isfinite(points).all(axis=1)
    if not placed.all():
        warnings.warn(f"{p}: {int((~placed).sum()):,} of {len(points):,} rows have no coordinates (missing or not "
                      "numbers) and are left out", ReadWarning, stacklevel=2)
        points, table = points[placed], table[placed]
    if not len(points):
        raise ReadError(p, "has no row with all its coordinates")
    if text:
        warnings.warn(f"{p}: columns of text left out: {', '.join(text[:20])}", ReadWarning, stacklevel=2)
    arrays: dict[str, Any] = {}
    for col in numeric:
        if col in columns:
            continue
        values = table[:, at[col]]
        check_finite(p, values, allow_nonfinite)
        arrays[names[col]] = values
    return UnstructuredMesh(points, [], point_data=arrays, source=str(p))  # points only: one vertex each
