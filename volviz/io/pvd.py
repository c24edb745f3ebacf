"""ParaView data collections (``.pvd``): the time series that ParaView, FEniCS, deal.II, SU2, LAMMPS, foamToVTK and
many in-house codes write as one small XML file listing VTK files with their times.

``<VTKFile type="Collection"><Collection><DataSet timestep="0.5" part="0" file="out_0001.vtu"/> ...``: every
``DataSet`` names a file (relative to the collection's folder) and optionally its ``timestep`` (0 when absent), its
``part`` and ``group``. Files of one time step are the parts of that step (one per process of a parallel run) and
are merged into one data set; several time steps become a ``TimeSeries`` whose frames are read lazily, each member
file through ``volviz.io.read`` with its own format's checks. Meshes may change from step to step (adaptive
refinement): a step is shown as read, and display times between two such steps show the earlier one.

Everything is checked before a member is read: the markup parses (expat, which refuses entity expansion bombs),
every ``timestep`` is a finite number, every listed file exists and is not itself a collection.
"""
from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io import read
from volviz.io._checks import check_file, describe_bytes, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError, human_bytes
from volviz.io.vtkconvert import vtk_to_model
from volviz.model import TimeSeries

MAX_COLLECTION_BYTES = 64 << 20  # a listing of files; a larger .pvd is not one


def is_pvd(head: bytes) -> bool:
    """A VTK XML file of ``type="Collection"``."""
    start = head.find(b"<VTKFile")
    return start >= 0 and b'type="Collection"' in head[start:start + 512]


def _number(path: Path, index: int, element: ET.Element, name: str, default: float) -> float:
    text = element.get(name)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise ReadError(path, f"DataSet {index + 1}: its {name} is {describe_bytes(text)}, not a number") from None
    if not math.isfinite(value):
        raise ReadError(path, f"DataSet {index + 1}: its {name} is not finite")
    return value


def collection_steps(path: PathLike) -> tuple[np.ndarray, list[list[Path]]]:
    """The collection's times (increasing) and, per time, its files (in the order of their ``part``, then as
    listed); ReadError for anything malformed or missing."""
    p = check_file(path)
    size = file_size(p)
    if size > MAX_COLLECTION_BYTES:
        raise ReadError(p, f"is {human_bytes(size)}; a .pvd collection lists files and is far smaller "
                           f"(at most {human_bytes(MAX_COLLECTION_BYTES)} is read)")
    data = read_bytes(p)
    if not is_pvd(data[:4096]):
        raise ReadError(p, f'is not a ParaView data collection (no <VTKFile type="Collection">; its content is '
                           f"{describe_bytes(data[:4096])})")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise ReadError(p, f"its XML does not parse ({exc})") from None
    listing = root.find("Collection")
    entries = list(listing.iter("DataSet")) if listing is not None else []
    if not entries:
        raise ReadError(p, "lists no data set (no <Collection><DataSet file=...> element)")
    steps: dict[float, list[tuple[float, int, Path]]] = defaultdict(list)
    for index, element in enumerate(entries):
        name = element.get("file")
        if not name or "\x00" in name:
            raise ReadError(p, f"DataSet {index + 1} names no file")
        member = Path(name) if os.path.isabs(name) else p.parent / name
        if member.suffix.lower() == ".pvd":
            raise ReadError(p, f"DataSet {index + 1} is itself a collection ({name}); collections do not nest")
        if not member.exists():
            raise ReadError(p, f"DataSet {index + 1} (time {element.get('timestep', '0')}): its file {name} is "
                               f"missing (looked for {member})")
        time = _number(p, index, element, "timestep", 0.0)
        steps[time].append((_number(p, index, element, "part", 0.0), index, member))
    times = sorted(steps)
    return np.asarray(times, dtype=np.float64), [[m for _, _, m in sorted(steps[t])] for t in times]


def _read_step(path: PathLike, members: list[Path], allow_nonfinite: bool) -> Any:
    """One time step: its one file, or its parts merged into one unstructured data set."""
    datasets = [read(member, isolate=False, allow_nonfinite=allow_nonfinite) for member in members]
    for member, dataset in zip(members, datasets):
        if isinstance(dataset, TimeSeries):
            raise ReadError(member, f"is itself a time series; a member of the collection {Path(path).name} must "
                                    "be one data set")
    if len(datasets) == 1:
        return datasets[0]
    import pyvista as pv  # heavy: PyVista and VTK, loaded only when a .pvd series is read

    return vtk_to_model(path, pv.MultiBlock([d.to_pyvista() for d in datasets]), allow_nonfinite)


def read_pvd(path: PathLike, time_index: int | None = None, allow_nonfinite: bool = True) -> Any:
    """A ``.pvd`` collection: one data set (one time step, or ``time_index``) or a TimeSeries over its time steps,
    step 0 read now and the others when shown."""
    times, steps = collection_steps(path)
    if time_index is not None:
        if not 0 <= time_index < len(steps):
            raise ReadError(path, f"time_index {time_index} is out of range: the collection has {len(steps)} time "
                                  "step(s)")
        return _read_step(path, steps[time_index], allow_nonfinite)
    first = _read_step(path, steps[0], allow_nonfinite)
    if len(steps) == 1:
        return first

    def load(index: int) -> Any:
        frame = _read_step(path, steps[index], allow_nonfinite)
        if type(frame) is not type(first):
            raise ReadError(steps[index][0], f"time step {index} is a {getattr(frame, 'kind', '?')}, but step 0 is "
                                             f"a {first.kind}")
        return frame

    return TimeSeries(times, [first] + [None] * (len(steps) - 1), loader=load, source=str(path))
