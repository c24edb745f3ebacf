"""Numbered files as one time series: a file with enough numbered siblings is opened as the whole series (as
ParaView groups numbered files); the pattern names them (``volviz.io.series`` reads it)."""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Optional

from volviz.io import ReadError
from volviz.io.folders import MIN_SERIES_FILES, numbered_pattern
from volviz.io.registry import spec_of


def series_pattern(path: str | os.PathLike) -> Optional[str]:
    """``Storm.pvm-t%02d`` for ``Storm.pvm-t01`` when at least three numbered siblings exist (opened as one time
    series, as ParaView groups numbered files); None otherwise, and for folders and for files whose reader reads
    them with their siblings (``ReaderSpec.reads_siblings``: the slices of a DICOM series)."""
    p = Path(path)
    if not p.is_file() or _reads_siblings(p):
        return None
    match = re.search(r"(\d+)(?!.*\d)", p.name)
    if match is None:
        return None
    head, tail = p.name[:match.start()], p.name[match.end():]
    rx = re.compile(re.escape(head) + r"(\d+)" + re.escape(tail) + r"\Z")
    try:
        siblings = [name for name in os.listdir(p.parent) if rx.match(name)]
    except OSError:
        return None
    if len(siblings) < MIN_SERIES_FILES:
        return None
    numbers = [rx.match(name).group(1) for name in siblings]  # type: ignore[union-attr]
    return str(p.parent.resolve() / numbered_pattern(head, numbers, tail))


def _reads_siblings(path: Path) -> bool:
    try:
        return spec_of(path).reads_siblings
    except ReadError:
        return False
