"""A cheap check of a Tecplot ASCII file's zones before VTK's vtkTecplotReader sees it: every zone must hold as many
values as its header says. VTK's reader loops for minutes on a zone cut short, or silently returns an empty or partial
mesh; a truncated file is refused here with the zone named.

Each zone header (``ZONE`` up to its first line of numbers) gives the counts (Tecplot 360 Data Format Guide, "ASCII
data"): ordered zones ``I x J x K`` points and ``max(I-1, 1) x max(J-1, 1) x max(K-1, 1)`` cells, finite-element zones
``N`` nodes and ``E`` elements of ``ET`` / ``ZONETYPE``; ``DATAPACKING`` (``F``) POINT or BLOCK; ``VARLOCATION``
cell-centred variables (one value per cell, BLOCK only); and an FE zone's connectivity (E x nodes per element) after
the values. A zone without numbers is refused whatever its header. The numbers up to the next record (a line starting
with a letter) are counted, ``n*value`` counting n.
Zones with shared variables or connectivity, polygonal/polyhedral zones, or anything this check does not know, are
left to VTK.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from volviz.io.errors import PathLike, ReadError

_PARAM = re.compile(r'([A-Za-z]+)\s*=\s*("[^"]*"|\([^)]*\)|[^,\s]+)')
_NODES_PER_ELEMENT = {"LINESEG": 2, "TRIANGLE": 3, "QUADRILATERAL": 4, "TETRAHEDRON": 4, "BRICK": 8,
                      "FELINESEG": 2, "FETRIANGLE": 3, "FEQUADRILATERAL": 4, "FETETRAHEDRON": 4, "FEBRICK": 8}
#: a count of a zone header with nothing after its '=' (VTK's reader took the default, 1, for a damaged "J=2")
#: a value of a zone (a number, ``n*value`` for n repeats; Fortran's ``D`` exponent too; NaN and infinities, which
#: a writer of floats may print and the reader draws as missing)
_VALUE = re.compile(r"(\d+\*)?[-+]?((\d+\.?\d*|\.\d+)([eEdD][-+]?\d+)?|nan|inf(inity)?)", re.IGNORECASE)
_COUNTS = ("I", "J", "K", "NODES", "N", "ELEMENTS", "E")
_EMPTY_COUNT = re.compile(r"(?<![A-Za-z])(I|J|K|N|E|NODES|ELEMENTS)\s*=\s*(?=,|$)", re.IGNORECASE)
_UNCHECKED = ("VARSHARELIST", "CONNECTIVITYSHAREZONE", "PASSIVEVARLIST", "FACES", "TOTALNUMFACENODES")


@dataclass
class _Zone:
    title: str
    header: str
    line: int
    values: int = 0


def _cell_centred(path: Path, zone: _Zone, varlocation: str, n_vars: int) -> set[int]:
    """The 0-based indices of the variables ``VARLOCATION=([4,5-6]=CELLCENTERED, ...)`` makes cell-centred; a
    variable number outside 1..n_vars is refused (a range up to 2^31 once took seconds and gigabytes here)."""
    found: set[int] = set()
    for group, where in re.findall(r"\[([^\]]*)\]\s*=\s*(\w+)", varlocation):
        for part in group.split(","):
            lo, _, hi = part.strip().partition("-")
            if not lo.strip().isdigit() or (hi and not hi.strip().isdigit()):
                continue
            first, last = int(lo), int(hi or lo)
            if not 1 <= first <= last <= n_vars:
                raise ReadError(path, f"{zone.title}, at line {zone.line}: VARLOCATION names variables "
                                      f"{part.strip()} but the file has {n_vars} variables (1 to {n_vars})")
            if where.upper() == "CELLCENTERED":
                found.update(range(first - 1, last))
    return found


def _needed(path: Path, zone: _Zone, n_vars: int) -> tuple[int, str] | None:
    """(values the zone's header asks for, what they are in words), or None when this check cannot tell; a
    negative count is refused (VTK's reader ran out of memory or time on one)."""
    params = {k.upper(): v.strip('"') for k, v in _PARAM.findall(zone.header)}
    empty = _EMPTY_COUNT.search(zone.header)
    if empty:
        raise ReadError(path, f"{zone.title}, at line {zone.line}: {empty.group(1).upper()}= has no value; a count "
                              "must be a whole number")
    for key in _COUNTS:
        if key in params and not re.fullmatch(r"[-+]?\d+", params[key]):
            raise ReadError(path, f"{zone.title}, at line {zone.line}: {key}={params[key][:40]}; a count must be a "
                                  "whole number")
    if any(k in params for k in _UNCHECKED):
        return None
    packing = params.get("DATAPACKING", params.get("F", "POINT")).upper()
    kind = params.get("ZONETYPE", params.get("ET", "ORDERED")).upper()
    try:
        if kind == "ORDERED":
            dims = [int(params.get(k, "1")) for k in ("I", "J", "K")]
            points, cells, per_cell = math.prod(dims), math.prod(max(d - 1, 1) for d in dims), 0
            shape = "x".join(map(str, dims)) + " points"
        elif kind in _NODES_PER_ELEMENT:
            points = int(params.get("NODES", params.get("N", "-1")))
            cells = int(params.get("ELEMENTS", params.get("E", "-1")))
            per_cell = _NODES_PER_ELEMENT[kind]
            shape = f"{points} nodes, {cells} {kind.lower()} elements"
        else:
            return None
    except ValueError:
        return None
    counts = {k: params[k] for k in _COUNTS if k in params}
    for key, value in counts.items():
        if value.lstrip("-").isdigit() and int(value) < 0:
            raise ReadError(path, f"{zone.title}, at line {zone.line}: {key}={value}; a count cannot be negative")
    if packing not in ("POINT", "BLOCK", "FEPOINT", "FEBLOCK"):
        return None
    centred = _cell_centred(path, zone, params.get("VARLOCATION", ""), n_vars) if "BLOCK" in packing else set()
    values = sum(cells if i in centred else points for i in range(n_vars)) + cells * per_cell
    return values, f"{n_vars} variables on {shape}" + (" and their connectivity" if per_cell else "")


def _count(line: str) -> int:
    tokens = line.replace(",", " ").split()
    if "*" not in line:
        return len(tokens)
    total = 0
    for token in tokens:
        repeat, star, _ = token.partition("*")
        total += int(repeat) if star and repeat.isdigit() else 1
    return total


def _variables(text: str) -> int:
    quoted = re.findall(r'"[^"]*"', text)
    return len(quoted) if quoted else len([t for t in re.split(r"[,\s]+", text) if t])


def check_tecplot_zones(path: PathLike, max_bytes: int = 1 << 31) -> None:
    """ReadError naming the zone when a zone of the Tecplot ASCII file at ``path`` holds fewer values than its
    header says, or when the file has no zone at all (files larger than ``max_bytes`` are left to VTK)."""
    p = Path(path)
    if p.stat().st_size > max_bytes:
        return
    zones: list[_Zone] = []
    variables, in_header = "", ""
    with open(p, "r", encoding="latin-1") as f:
        for number, raw in enumerate(f, 1):
            line = raw.strip()
            if not line or line.startswith("#"):
                continue
            first = line[0]
            if first.isalpha() or first == '"':
                word = line.split("=", 1)[0].split()[0].upper() if first.isalpha() else ""
                if word == "ZONE":
                    zones.append(_Zone("", line[4:], number))
                    in_header = "zone"
                elif word == "VARIABLES":
                    variables, in_header = line.split("=", 1)[-1], "variables"
                elif first == '"' and in_header == "variables":
                    variables += " " + line
                elif in_header == "zone" and zones:
                    zones[-1].header += " " + line
                else:
                    in_header = ""
                continue
            in_header = ""
            if zones:
                bad = next((t for t in line.replace(",", " ").split() if not _VALUE.fullmatch(t)), None)
                if bad is not None:
                    raise ReadError(p, f"line {number} holds {bad[:40]!r} among the values of zone {len(zones)}; "
                                       "a value must be a number")
                zones[-1].values += _count(line)
    n_vars = _variables(variables)
    if not zones:
        raise ReadError(p, "holds no ZONE: a Tecplot file without data", "check the file was written completely")
    for index, zone in enumerate(zones, 1):
        m = re.search(r'\bT\s*=\s*"([^"]*)"', zone.header)
        zone.title = f"zone {index}" + (f" ({m.group(1)})" if m else "")
        needed = _needed(p, zone, n_vars) if n_vars else None
        if zone.values == 0:
            raise ReadError(p, f"{zone.title}, at line {zone.line}, holds no values: the file is truncated",
                            "write the file again completely")
        if needed is not None and zone.values < needed[0]:
            raise ReadError(p, f"{zone.title}, at line {zone.line}, holds {zone.values} values where its header "
                               f"needs {needed[0]} ({needed[1]}): the file is truncated or the zone header is wrong",
                            "write the file again completely")
        if needed is not None and zone.values > needed[0]:
            raise ReadError(p, f"{zone.title}, at line {zone.line}, holds {zone.values} values where its header "
                               f"needs {needed[0]} ({needed[1]}): the zone header is wrong")
