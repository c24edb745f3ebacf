"""What opening a folder shows when no reader opens the folder itself (a DICOM series, an OpenFOAM case, an OME-Zarr
image do): a simulation's output folder, as ParaView's file dialog groups it.

- Its one collection file -- a ParaView ``.pvd``, an XDMF ``.xdmf`` / ``.xmf``, a ``.vtm`` / ``.vtpd`` multiblock,
  an OpenFOAM ``.foam`` or EnSight ``.case`` file -- which lists the rest of the folder's data;
- else its largest numbered series of files volviz reads (``out_0000.vtu`` ... at least ``MIN_SERIES_FILES``), as
  the printf pattern ``out_%04d.vtu`` that ``volviz.io.read`` opens as a time series.
"""
from __future__ import annotations

import os
import re
from collections import defaultdict
from pathlib import Path

from volviz.io.errors import PathLike, ReadError
from volviz.io.registry import spec_of

COLLECTION_SUFFIXES = (".pvd", ".xdmf", ".xmf", ".vtm", ".vtpd", ".foam", ".case")
MIN_SERIES_FILES = 3          # numbered files that make a series (fewer are separate files)
_LAST_NUMBER = re.compile(r"(\d+)(?!.*\d)")


def numbered_pattern(head: str, numbers: list[str], tail: str) -> str:
    """The printf pattern of files ``head + n + tail``: zero-padded when every number has the same width and one
    starts with 0 (``t%02d``), else ``%d``."""
    widths = {len(n) for n in numbers}
    padded = len(widths) == 1 and any(n.startswith("0") and len(n) > 1 for n in numbers)
    return f"{head}%0{widths.pop()}d{tail}" if padded else f"{head}%d{tail}"


def folder_target(folder: PathLike) -> str | None:
    """The collection file or numbered series pattern opening ``folder`` shows (see the module), or None."""
    try:
        files = sorted((entry for entry in os.scandir(folder) if entry.is_file()), key=lambda e: e.name)
    except OSError:
        return None
    collections = [f.path for f in files if f.name.lower().endswith(COLLECTION_SUFFIXES)]
    if len(collections) == 1:
        return collections[0]
    groups: dict[tuple[str, str], list[tuple[int, str, str]]] = defaultdict(list)
    for f in files:
        m = _LAST_NUMBER.search(f.name)
        if m:
            groups[(f.name[:m.start()], f.name[m.end():])].append((int(m.group(1)), m.group(1), f.path))
    for (head, tail), members in sorted(groups.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        if len(members) < MIN_SERIES_FILES:
            break
        try:
            spec_of(min(members)[2])
        except ReadError:
            continue
        return str(Path(folder) / numbered_pattern(head, [n for _, n, _ in members], tail))
    return None
