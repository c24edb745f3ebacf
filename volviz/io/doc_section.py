"""A generated section of a shared document: the text between a ``begin`` and an ``end`` marker line.

Several generators write into one markdown report (``docs/first-open.md``: the app's window table and ``volviz
bench first_open``'s render table). Each owns only the text between its own markers, so regenerating one keeps the
others' sections and the hand-written prose around them. Writes are atomic (``volviz.io.atomic``).
"""
from __future__ import annotations

from pathlib import Path

from volviz.io.atomic import atomic_write_text


class SectionError(ValueError):
    """A document whose markers of a section are broken (one without the other, or the end before the begin)."""


def _span(path: Path, old: str, begin: str, end: str) -> tuple[int, int] | None:
    """Where the section (its markers included) lies in ``old``; None when neither marker is there."""
    start, stop = old.find(begin), old.find(end)
    if start < 0 and stop < 0:
        return None
    if start < 0 or stop < 0 or stop < start:
        raise SectionError(f"{path}: the section markers {begin!r} and {end!r} are broken (one is missing or they "
                           "are out of order); mend or remove them by hand")
    return start, stop + len(end)


def read_section(path: Path, begin: str, end: str) -> str:
    """The text between the markers of ``path`` (without them); '' when the file or the section is absent."""
    path = Path(path)
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    span = _span(path, old, begin, end)
    return "" if span is None else old[span[0] + len(begin):span[1] - len(end)].strip("\n")


def write_section(path: Path, begin: str, end: str, body: str) -> None:
    """Put ``body`` between the markers of ``path``, keeping everything outside them; a file without the section
    gets it appended (a missing file is created with it)."""
    path = Path(path)
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    section = f"{begin}\n\n{body.strip(chr(10))}\n\n{end}"
    span = _span(path, old, begin, end)
    if span is None:
        new = (old.rstrip("\n") + "\n\n" if old.strip() else "") + section + "\n"
    else:
        new = old[:span[0]] + section + old[span[1]:]
    atomic_write_text(path, new)


def _row_name(line: str) -> str | None:
    """The file a table row is about: the first code span of a line ``| `NAME` | ...``; None for other lines."""
    return line.split("`")[1] if line.startswith("| `") and line.count("`") >= 2 else None


def merge_rows(old: str, new: str, order: list[str]) -> str:
    """``new`` (a section whose table has rows for some files only: a run over a few of them) with the rows of
    ``old`` kept for the files it has no row for, all rows in ``order`` (the names of every file, in table order;
    others after them). The table is the first run of lines that begin ``| `NAME` |``, or that follow the
    ``|---|`` line."""
    kept = {name: line for line in old.splitlines() if (name := _row_name(line)) is not None}
    lines = new.splitlines()
    start = next((i + 1 for i, line in enumerate(lines) if line.startswith("|---")), len(lines))
    stop = start
    while stop < len(lines) and _row_name(lines[stop]) is not None:
        stop += 1
    rows = dict(kept)
    for line in lines[start:stop]:
        rows[str(_row_name(line))] = line
    ranked = sorted(rows, key=lambda n: (order.index(n) if n in order else len(order), n))
    return "\n".join(lines[:start] + [rows[n] for n in ranked] + lines[stop:]) + "\n"
