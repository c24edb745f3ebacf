"""How the first look draws a dataset: one rule, from the data's shape and its shown field's variation (issue #30).

A first image is never blank and never meaningless:

- a mesh of vertices only is drawn as **points**;
- a mesh without solid cells, a grid one layer thick (a 72 x 45 x 1 netCDF field, a 2D simulation) is a **surface**:
  a volume one sample thick has no depth to integrate over and drew as an empty box;
- a dataset that shows no field (a mesh with only block ids, an STL) is a **surface** in a plain colour;
- a constant field (one value everywhere, or no finite value) is a **surface** too, and says so: a transfer function
  has nothing to tell apart, and the volume drew as uniform fog or not at all;
- everything else is a **volume**.

A time series whose first step is constant starts at the first step where the field varies
(``first_varying_step``). Nothing here draws: ``volviz.render`` asks ``representation`` and draws what it says.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Union

import numpy as np

from volviz.model.arrays import array_info, default_array
from volviz.model.datasets import CurvilinearGrid, Dataset, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh
from volviz.model.object_cache import ObjectCache

VOLUME, SURFACE, POINTS = "volume", "surface", "points"

#: VTK cell types of solid cells (tetrahedron, voxel, hexahedron, wedge, pyramid, pentagonal and hexagonal prisms,
#: their quadratic forms, polyhedron): a mesh holding any has a volume to draw
SOLID_CELL_TYPES = frozenset({10, 11, 12, 13, 14, 15, 16, 24, 25, 26, 27, 29, 32, 33, 42})
#: VTK vertex and poly-vertex: a mesh of these only is a point cloud
POINT_CELL_TYPES = frozenset({1, 2})
#: the most time steps ``first_varying_step`` reads looking for one that varies
MAX_STEPS_SCANNED = 64


@dataclass(frozen=True)
class Representation:
    """What the first look draws: ``kind`` (``VOLUME``, ``SURFACE`` or ``POINTS``), the shown ``field`` (None: plain
    geometry), whether that field is ``constant`` (its one ``value``), and ``reason``: why it is not a volume, in
    words ('' for a volume)."""

    kind: str
    field: Optional[str]
    constant: bool = False
    value: float = float("nan")
    reason: str = ""


def shown_field(dataset: Union[Dataset, TimeSeries]) -> tuple[Optional[str], Optional[np.ndarray]]:
    """The name and values of the field ``dataset`` shows (its active array, as ``volviz.model.arrays.select_array``
    sets it; a regular volume's data, a tetrahedral mesh's scalars); (None, None) for geometry alone."""
    if isinstance(dataset, RegularVolume):
        return dataset.name, dataset.data
    if isinstance(dataset, TetMesh):
        return dataset.name, dataset.scalars
    if isinstance(dataset, (UnstructuredMesh, CurvilinearGrid)):
        name = dataset.active
        if name is None:
            return None, None
        values = dataset.point_data.get(name)
        if values is None:
            values = dataset.cell_data.get(name)
        return (name, None) if values is None else (name, np.asarray(values))
    return None, None


def field_range(values: np.ndarray) -> tuple[float, float]:
    """The finite min and max of ``values`` (of the magnitude for vectors); NaN, NaN when none is finite."""
    values = np.asarray(values)
    if values.dtype.kind not in "biuf" or values.size == 0:
        return float("nan"), float("nan")
    if values.dtype.kind == "f":
        finite = np.isfinite(values)
        if not finite.all():
            values = values[finite]
            if values.size == 0:
                return float("nan"), float("nan")
    return float(values.min()), float(values.max())


def _varies(lo: float, hi: float) -> bool:
    return bool(np.isfinite(lo) and np.isfinite(hi) and hi > lo)


#: each dataset's representation, kept while it lives (``representation``)
_REPRESENTATIONS: ObjectCache[Representation] = ObjectCache()


def _shape_kind(dataset: Any) -> tuple[str, str]:
    """The kind the data's shape allows, and why it is not a volume."""
    if isinstance(dataset, UnstructuredMesh):
        types = {int(t) for t, c in dataset.cells if len(c)}
        if types and types <= POINT_CELL_TYPES:
            return POINTS, "a point cloud"
        if not types & SOLID_CELL_TYPES:
            return SURFACE, "a mesh without solid cells"
    if isinstance(dataset, (CurvilinearGrid, RegularVolume)):
        dims = tuple(int(d) for d in (dataset.dimensions if isinstance(dataset, CurvilinearGrid)
                                      else dataset.data.shape[:3]))
        if min(dims) < 2:
            return SURFACE, f"a single-layer grid ({' x '.join(str(d) for d in dims)})"
    return VOLUME, ""


def representation(dataset: Union[Dataset, TimeSeries]) -> Representation:
    """How the first look draws ``dataset`` (see the module docstring); a time series as at its first step where the
    field varies. Kept for the dataset while it lives, so the many callers of one scene pay once."""
    cached = _REPRESENTATIONS.get(dataset)
    if cached is not None:
        return cached
    if isinstance(dataset, TimeSeries):
        step = first_varying_step(dataset)
        shown = representation(dataset.frame(step or 0))
    else:
        shown = _representation(dataset)
    return _REPRESENTATIONS.put(dataset, shown)


def _representation(dataset: Any) -> Representation:
    kind, reason = _shape_kind(dataset)
    name, values = shown_field(dataset)
    if name is None and isinstance(dataset, (UnstructuredMesh, CurvilinearGrid)):   # as read: its default array
        return _by_default_array(dataset, kind, reason)
    if name is None or values is None:
        if isinstance(dataset, (UnstructuredMesh, CurvilinearGrid)):
            return Representation(POINTS if kind == POINTS else SURFACE, None,
                                  reason="no field to show: drawn as plain geometry")
        return Representation(kind, name, reason=reason)
    lo, hi = field_range(values)
    if not _varies(lo, hi):
        return _constant(kind, name, lo)
    return Representation(kind, name, reason=reason)


def _by_default_array(dataset: Any, kind: str, reason: str) -> Representation:
    """A dataset as read (no array chosen yet) drawn through its default array (``arrays.default_array``)."""
    spec = default_array(dataset)
    if spec is None:
        return Representation(POINTS if kind == POINTS else SURFACE, None,
                              reason="no field to show: drawn as plain geometry")
    info = array_info(dataset, spec)
    assert info is not None  # the default is one of the dataset's arrays
    if not info.varies:
        return _constant(kind, spec, info.range[0])
    return Representation(kind, spec, reason=reason)


def _constant(kind: str, name: str, value: float) -> Representation:
    said = f"{value:g} everywhere" if np.isfinite(value) else "no finite value"
    return Representation(POINTS if kind == POINTS else SURFACE, name, True, value,
                          f"the field {name} is constant ({said}): drawn as a surface")


def first_varying_step(series: TimeSeries) -> Optional[int]:
    """The first step (of at most ``MAX_STEPS_SCANNED``) whose shown field varies; 0 when the first does, None when
    none of those scanned does (or none shows a field)."""
    for i in range(min(len(series), MAX_STEPS_SCANNED)):
        shown = representation(series.frame(i))
        if shown.field is None:
            return None
        if not shown.constant:
            return i
    return None
