"""A cheap check of an EnSight case before VTK's vtkGenericEnSightReader sees it: the case file's sections, the files
it names and what the geometry and variable files hold against what their counts say.

VTK's reader loops until its time limit on a case file with a damaged section line, and reads a geometry or variable
file cut short as other values (issue #32: 27 damaged files accepted, 4 refusals after 10 s). Checked here (EnSight
Gold User Manual, "EnSight Gold Case File Format", "Geometry File Format", "Variable File Format"):

- the case file: only known sections (FORMAT, GEOMETRY, VARIABLE, TIME, FILE, MATERIAL, BLOCK_CONTINUATION,
  SCRIPTS) and ``key: value`` lines known in each; ``type: ensight gold`` (or ``ensight`` for EnSight 6); a GEOMETRY
  ``model:``; each time set's ``number of steps`` equals its ``time values`` (and ``filename numbers``) count;
- every file named exists, a ``*`` wildcard expanded for each step (start number + increment, or the numbers);
- Gold geometry, ASCII (one value a line) or ``C Binary``: each part's node count and each element block's count
  against the lines or bytes left; a line where a part or element type must be that is not one is refused;
- Gold variables per node / per element, ASCII or C Binary: each part's values against the geometry's counts.
Structured (``block``) parts, polygons/polyhedra (``nsided``/``nfaced``), Fortran binary and file sets (FILE section)
end the detailed check there: VTK reads what follows.
"""
from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field
from pathlib import Path

from volviz.io.errors import PathLike, ReadError

_SECTIONS = {"FORMAT", "GEOMETRY", "VARIABLE", "TIME", "FILE", "MATERIAL", "BLOCK_CONTINUATION", "SCRIPTS"}
_GEOMETRY_KEYS = {"model", "measured", "match", "boundary", "rigid_body", "vector_glyphs"}
_TIME_KEYS = {"time set", "number of steps", "filename start number", "filename increment", "filename numbers",
              "time values", "filename numbers file", "time values file"}
_VARIABLE = re.compile(r"(constant per case( file)?|(complex )?(scalar|vector|tensor symm|tensor asym|tensor9)"
                       r" per (measured )?(node|element))$")
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")    # none in a case file VTK reads as meant
_COMPONENTS = {"scalar": 1, "vector": 3, "tensor symm": 6, "tensor asym": 9, "tensor9": 9}
NODES_PER_ELEMENT = {"point": 1, "bar2": 2, "bar3": 3, "tria3": 3, "tria6": 6, "quad4": 4, "quad8": 8,
                     "tetra4": 4, "tetra10": 10, "pyramid5": 5, "pyramid13": 13, "penta6": 6, "penta15": 15,
                     "hexa8": 8, "hexa20": 20}
_UNCHECKED_ELEMENTS = {"nsided", "nfaced", "g_nsided", "g_nfaced"}
MAX_ASCII_BYTES = 256 << 20          # larger ASCII files are left to VTK (walking their lines costs seconds)


@dataclass
class TimeSet:
    steps: int = 1
    start: int = 0
    increment: int = 1
    numbers: list[int] = field(default_factory=list)
    values: list[float] = field(default_factory=list)
    external: bool = False                              # numbers or values in a file of their own: not checked


@dataclass
class Case:
    gold: bool = True
    geometry: tuple[int | None, str] | None = None          # (time set, file name)
    variables: list[tuple[str, int | None, str]] = field(default_factory=list)   # (kind, time set, file name)
    times: dict[int, TimeSet] = field(default_factory=dict)
    file_sets: bool = False


@dataclass
class Part:
    nodes: int
    elements: list[tuple[str, int]] = field(default_factory=list)
    checked: bool = True                                    # False: a structured part or polyhedra, not walked


def _int(p: Path, text: str, what: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ReadError(p, f"{what} is {text!r}, not a whole number") from None


def _words(text: str) -> list[str]:
    return [w for w in re.split(r"[ \t]+", text) if w]


def _split_names(rest: str) -> tuple[list[int], list[str]]:
    """Leading set numbers and the remaining tokens of a GEOMETRY / VARIABLE line's value."""
    tokens = _words(rest)
    numbers = []
    while tokens and tokens[0].isdigit() and len(tokens) > 1:
        numbers.append(int(tokens.pop(0)))
    return numbers, tokens


def parse_case(path: PathLike) -> Case:
    """The case file's contents, every line known or a ReadError naming the line."""
    p = Path(path)
    case, section, last_key, ts = Case(), "", "", None
    fmt, entries = "", 0
    for number, raw in enumerate(p.read_text(encoding="latin-1").split("\n"), 1):
        line = raw.split("#", 1)[0].strip(" \t\r")
        bad = _CONTROL.search(line)
        if bad:
            raise ReadError(p, f"line {number} of the case file holds the byte {bad.group(0)!r}: the file is damaged")
        if not line:
            continue
        if ":" not in line:
            if line in _SECTIONS:
                _check_not_empty(p, section, entries)
                section, last_key, entries = line, "", 0
                continue
            if section == "TIME" and last_key in ("time values", "filename numbers") and ts is not None:
                _continue_list(p, case.times[ts], last_key, line, number)
                continue
            raise ReadError(p, f"line {number} of the case file ({line[:40]!r}) is neither a section nor a "
                               "'key: value' line")
        key, rest = (s.strip(" \t") for s in line.split(":", 1))
        entries += 1
        if rest and line[len(line.split(":", 1)[0]) + 1] not in " \t":
            raise ReadError(p, f"line {number} of the case file ({line[:40]!r}) has no space after its ':'")
        key = " ".join(_words(key))
        if section == "FORMAT" and key == "type":
            fmt = " ".join(_words(rest))
            if fmt not in ("ensight gold", "ensight"):
                raise ReadError(p, f"FORMAT type is {rest!r}; EnSight case files are 'ensight gold' or 'ensight'")
            case.gold = fmt == "ensight gold"
        elif section == "GEOMETRY" and key in _GEOMETRY_KEYS:
            if key == "model":
                sets, names = _split_names(rest)
                if not names:
                    raise ReadError(p, f"line {number}: the GEOMETRY model line names no file")
                case.geometry = (sets[0] if sets else None, names[0])
        elif section == "VARIABLE" and _VARIABLE.match(key):
            sets, names = _split_names(rest)
            if len(names) < 2:
                raise ReadError(p, f"line {number}: the VARIABLE {key!r} line needs a description and a file name, "
                                   f"it holds {rest!r}")
            if not key.startswith("constant per case") or key.endswith("file"):
                kind = key if not key.startswith("complex") else "complex"
                for name in names[1:3] if kind == "complex" else names[-1:]:
                    case.variables.append((kind, sets[0] if sets else None, name))
        elif section == "TIME" and key in _TIME_KEYS:
            last_key = key
            if key == "time set":
                ts = _int(p, rest.split()[0] if rest.split() else "", f"line {number}: 'time set'")
                case.times[ts] = TimeSet()
                continue
            if ts is None:                               # EnSight 6 / single time set without 'time set:'
                ts = 1
                case.times[ts] = TimeSet()
            t = case.times[ts]
            if key == "number of steps":
                t.steps = _int(p, rest, f"time set {ts}: 'number of steps'")
                if t.steps < 1:
                    raise ReadError(p, f"time set {ts}: 'number of steps' is {t.steps}; it must be at least 1")
            elif key == "filename start number":
                t.start = _int(p, rest, f"time set {ts}: 'filename start number'")
            elif key == "filename increment":
                t.increment = _int(p, rest, f"time set {ts}: 'filename increment'")
            elif key in ("time values", "filename numbers"):
                _continue_list(p, t, key, rest, number)
            else:                                        # 'time values file:' / 'filename numbers file:'
                t.external = True
        elif section in ("FILE", "MATERIAL", "BLOCK_CONTINUATION", "SCRIPTS") and section:
            case.file_sets = case.file_sets or section == "FILE"
        else:
            raise ReadError(p, f"line {number} of the case file: {key!r} is not a key of the "
                               f"{section or 'missing'} section")
    _check_not_empty(p, section, entries)
    if not fmt:
        raise ReadError(p, "the case file has no FORMAT 'type:' line")
    if case.geometry is None:
        raise ReadError(p, "the case file names no geometry (no GEOMETRY 'model:' line)")
    for number, t in case.times.items():
        if t.external:
            continue
        if len(t.values) != t.steps:
            raise ReadError(p, f"time set {number}: 'number of steps' is {t.steps} but 'time values' holds "
                               f"{len(t.values)} values")
        if t.numbers and len(t.numbers) != t.steps:
            raise ReadError(p, f"time set {number}: 'number of steps' is {t.steps} but 'filename numbers' holds "
                               f"{len(t.numbers)} numbers")
    return case


def _check_not_empty(p: Path, section: str, entries: int) -> None:
    """A section holds a line: a case file cut right after a section's name reads as one without it."""
    if section and not entries:
        raise ReadError(p, f"the case file's {section} section is empty: the file is cut after its name or damaged")


def _continue_list(p: Path, t: TimeSet, key: str, text: str, line: int) -> None:
    try:
        if key == "time values":
            t.values += [float(v) for v in text.split()]
        else:
            t.numbers += [int(v) for v in text.split()]
    except ValueError:
        raise ReadError(p, f"line {line} of the case file: {key!r} holds {text[:40]!r}, not numbers") from None


def file_names(p: Path, case: Case, time_set: int | None, name: str, what: str) -> list[Path]:
    """The files a (possibly wildcard) name stands for, one per step of its time set."""
    if "*" not in name:
        return [p.parent / name]
    if time_set is None and len(case.times) == 1:
        time_set = next(iter(case.times))
    if time_set not in case.times:
        raise ReadError(p, f"the {what} file name {name!r} has a '*' wildcard but time set {time_set} is not defined")
    t = case.times[time_set]
    if t.external:
        return []
    numbers = t.numbers or [t.start + i * t.increment for i in range(t.steps)]
    stars = re.search(r"\*+", name)
    assert stars is not None
    width = len(stars.group(0))
    return [p.parent / (name[:stars.start()] + f"{n:0{width}d}" + name[stars.end():]) for n in numbers]


# -- geometry ----------------------------------------------------------------------------------------------------------
class _Lines:
    """An ASCII file's non-empty lines with their position, for counted reads."""

    def __init__(self, path: Path) -> None:
        text = path.read_text(encoding="latin-1").splitlines()
        numbered = [(n, ln) for n, ln in enumerate(text, 1) if ln.strip()]
        self.path, self.numbers, self.lines = path, [n for n, _ in numbered], [ln for _, ln in numbered]
        self.i = 0

    def at(self) -> int:
        """The file's line number of the line last read."""
        return self.numbers[self.i - 1] if self.i else 0

    EXTENTS = 3                                         # lines of 'xmin xmax' ...

    def more(self) -> bool:
        return self.i < len(self.lines)

    def where(self) -> str:
        return f"line {self.at()}"

    def before_parts(self, ahead: int = 0) -> None:
        pass

    def word(self, what: str) -> str:
        return self.next(what)

    def values(self, count: int, what: str) -> None:
        self.take(count, what)

    def elements(self, count: int, per_element: int, ids: bool, what: str) -> None:
        """``count`` connectivity lines of ``per_element`` node numbers each (after their ids when given)."""
        self.take(count if ids else 0, what + "' ids")
        start = self.i
        self.take(count, what)
        for k in range(start, self.i):
            found = len(self.lines[k].split())
            if found != per_element:
                raise ReadError(self.path, f"line {self.numbers[k]} of {what} holds {found} node numbers where "
                                           f"each has {per_element}: a count is wrong or the file is damaged")

    def next(self, what: str) -> str:
        if self.i >= len(self.lines):
            raise ReadError(self.path, f"ends where {what} should be: the file is truncated")
        self.i += 1
        return self.lines[self.i - 1].strip()

    def take(self, count: int, what: str) -> None:
        """Skip ``count`` lines of values, refused when fewer are left."""
        left = len(self.lines) - self.i
        if count > left:
            raise ReadError(self.path, f"{what} needs {count} lines of values but the file holds {left} more: the "
                                       "file is truncated or the count is wrong")
        self.i += count

    def count(self, what: str) -> int:
        n = _int(self.path, self.next(what), what)
        if n < 0:
            raise ReadError(self.path, f"{what} is {n}; a count cannot be negative")
        return n


class _Bytes:
    """A C Binary file's 80-byte strings, ints and floats read with the bytes left checked."""

    def __init__(self, path: Path) -> None:
        self.path, self.data, self.at, self.order = path, path.read_bytes(), 0, "<"

    def need(self, size: int, what: str) -> None:
        left = len(self.data) - self.at
        if size > left:
            raise ReadError(self.path, f"{what} needs {size} bytes but the file holds {left} more: the file is "
                                       "truncated or the count is wrong")

    EXTENTS = 6                                         # floats

    def more(self) -> bool:
        return self.at < len(self.data)

    def where(self) -> str:
        return f"byte {self.at - 80}"

    def before_parts(self, ahead: int = 0) -> None:
        """The byte order, told from the first part number (``ahead`` bytes on)."""
        self.order = _binary_order(self.data, self.at + ahead)

    def values(self, count: int, what: str) -> None:
        self.skip(4 * count, what)

    def elements(self, count: int, per_element: int, ids: bool, what: str) -> None:
        self.skip(4 * count * (per_element + (1 if ids else 0)), what)

    def word(self, what: str) -> str:
        self.need(80, what)
        self.at += 80
        return self.data[self.at - 80:self.at].split(b"\0", 1)[0].decode("latin-1").strip()

    def integer(self, what: str) -> int:
        self.need(4, what)
        self.at += 4
        return struct.unpack(self.order + "i", self.data[self.at - 4:self.at])[0]

    def count(self, what: str) -> int:
        n = self.integer(what)
        if n < 0:
            raise ReadError(self.path, f"{what} is {n}; a count cannot be negative")
        return n

    def skip(self, size: int, what: str) -> None:
        self.need(size, what)
        self.at += size


def _binary_order(data: bytes, at: int) -> str:
    """The byte order in which the int at ``at`` (a part number) is the smaller positive number."""
    little, big = (struct.unpack(o + "i", data[at:at + 4])[0] if len(data) >= at + 4 else 0 for o in "<>")
    return ">" if 0 < big < (little if little > 0 else 1 << 31) else "<"


def _walk_geometry(f: _Lines | _Bytes) -> dict[int, Part]:
    """The parts of a Gold geometry file, ASCII or C Binary alike: every count against what is left."""
    path = f.path
    if isinstance(f, _Bytes):
        f.word("'C Binary'")
    f.word("the first description"), f.word("the second description")
    given_nodes = f.word("the 'node id' line").lower().split()[-1:] in (["given"], ["ignore"])
    given_elements = f.word("the 'element id' line").lower().split()[-1:] in (["given"], ["ignore"])
    parts: dict[int, Part] = {}
    line = f.word("'part' or 'extents'")
    if line.lower() == "extents":
        f.values(f.EXTENTS, "'extents'")
        line = f.word("'part'")
    f.before_parts()
    while True:
        if line.lower() != "part":
            raise ReadError(path, f"{f.where()} is {line[:40]!r} where 'part' should be: a count before it is wrong")
        number = f.count("a part number")
        f.word(f"part {number}'s description")
        kind = f.word(f"part {number}'s 'coordinates'").lower()
        if kind.startswith("block"):
            parts[number] = Part(0, checked=False)
            return parts
        if kind != "coordinates":
            raise ReadError(path, f"{f.where()} is {kind[:40]!r} where part {number}'s 'coordinates' should be")
        part = parts[number] = Part(f.count(f"part {number}'s node count"))
        f.values(part.nodes * (4 if given_nodes else 3), f"part {number}'s {part.nodes} nodes")
        while f.more() or not part.elements:             # a part holds at least one element block
            line = f.word(f"part {number}'s first element type")
            kind = line.lower()
            if kind == "part" and part.elements:
                break
            if kind in _UNCHECKED_ELEMENTS:
                part.checked = False
                return parts
            npe = NODES_PER_ELEMENT.get(kind.removeprefix("g_"))
            if npe is None:
                raise ReadError(path, f"{f.where()} is {line[:40]!r} where an element type or 'part' should be: "
                                      f"a count before it is wrong (part {number} has {part.nodes} nodes)")
            ne = f.count(f"part {number}'s {kind} count")
            f.elements(ne, npe, given_elements, f"part {number}'s {ne} {kind} elements")
            part.elements.append((kind, ne))
        else:
            return parts


def check_geometry(path: Path) -> tuple[dict[int, Part], bool] | None:
    """The parts of a Gold geometry file walked against its counts, and whether it is C Binary (its variable
    files are then binary too); None for Fortran binary or a large ASCII file, not checked."""
    with open(path, "rb") as f:
        head = f.read(80).lower().lstrip()
    if head.startswith(b"c binary"):
        return _walk_geometry(_Bytes(path)), True
    if head.startswith(b"fortran binary") or path.stat().st_size > MAX_ASCII_BYTES:
        return None
    return _walk_geometry(_Lines(path)), False


# -- variables ---------------------------------------------------------------------------------------------------------
def _needed(part: Part, where: str, comps: int) -> list[tuple[str, int]]:
    """(what, values) the variable must hold for one part."""
    if where == "node":
        return [("coordinates", part.nodes * comps)]
    return [(kind, ne * comps) for kind, ne in part.elements]


def check_variable(path: Path, kind: str, parts: dict[int, Part], binary: bool) -> None:
    """A per-node or per-element Gold variable file's values per part against the geometry's counts."""
    words = kind.split()
    if kind == "complex" or "measured" in words or words[0] not in ("scalar", "vector", "tensor", "tensor9"):
        return
    comps = _COMPONENTS[" ".join(words[:2]) if words[0] == "tensor" else words[0]]
    if not binary and path.stat().st_size > MAX_ASCII_BYTES:
        return
    f: _Lines | _Bytes = _Bytes(path) if binary else _Lines(path)
    f.word("the description")
    f.before_parts(80)
    if not f.more():
        raise ReadError(path, f"holds its description line and no part (the geometry has parts {sorted(parts)}): "
                              "the file is truncated")
    while f.more():
        line = f.word("'part'")
        if line.lower() != "part":
            raise ReadError(path, f"{f.where()} is {line[:40]!r} where 'part' should be: the file holds more or "
                                  "fewer values than the geometry's counts")
        number = f.count("a part number")
        part = parts.get(number)
        if part is None:
            raise ReadError(path, f"part {number} is not a part of the geometry (parts {sorted(parts)})")
        if not part.checked:
            return
        for block, values in _needed(part, words[-1], comps):
            name = f.word(f"part {number}'s '{block}'").lower()
            if name != block:
                raise ReadError(path, f"{f.where()} is {name[:40]!r} where part {number}'s '{block}' should be")
            f.values(values, f"part {number}'s {block} ({values} values of the geometry's counts)")


def check_ensight_case(path: PathLike) -> None:
    """ReadError naming the file and the field when the case or a file it names does not hold what it says."""
    p = Path(path)
    case = parse_case(p)
    time_set, name = case.geometry or (None, "")
    geometries = file_names(p, case, time_set, name, "geometry")
    for g in geometries:
        if not g.is_file():
            raise ReadError(p, f"the geometry file {g.name} (GEOMETRY model {name!r}) does not exist")
    variables = [(kind, v, file_names(p, case, ts, v, "variable")) for kind, ts, v in case.variables]
    for kind, v, files in variables:
        for f in files:
            if not f.is_file():
                raise ReadError(p, f"the variable file {f.name} (VARIABLE {kind} {v!r}) does not exist")
    if not case.gold or case.file_sets:
        return
    walked = [check_geometry(g) for g in geometries]
    if len(walked) != 1 or walked[0] is None:
        return                                   # changing geometry: variables are checked by VTK's reader
    parts, binary = walked[0]
    for kind, _, files in variables:
        for f in files:
            check_variable(f, kind, parts, binary)
