"""The arrays a dataset offers and the choice of the one it shows.

A dataset keeps every point and cell array of its file. What a view draws is one scalar per point: a scalar array,
one component of a vector/tensor array, or its magnitude, named by an array spec ``NAME``, ``NAME:c`` (component
``c``, from 0) or ``NAME:magnitude``. A name on both the points and the cells (OpenFOAM's ``p`` and ``U``) is told
apart as ParaView's ``ColorBy(('CELLS', 'p'))`` does, by an association in the spec: ``NAME@cells`` (``@points``)
before the component, ``U@cells:0``; a spec without one names the point array when there is one. Cell arrays are
shown as point scalars through VTK's cell-to-point filter (the average of the cells around each point, as ParaView
does). Non-finite values are kept and counted; the renderers draw them transparent.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Optional, Union, overload

import numpy as np

from volviz.model.datasets import (CurvilinearGrid, Dataset, Image2D, RegularVolume, TetMesh, TimeSeries,
                                   UnstructuredMesh)

MAGNITUDE = "magnitude"
MAX_COMPONENTS = 9           # tensors: 3x3


#: the association words of a spec (``NAME@cells``) -> ``ArrayInfo.association``; the plural is the one written
ASSOCIATIONS = {"points": "point", "point": "point", "cells": "cell", "cell": "cell"}


@dataclass(frozen=True)
class ArraySpec:
    """A parsed array spec: the array's ``name``, ``component`` (an index, ``"magnitude"``, or None for a
    scalar array / the default of a vector: its magnitude) and ``association`` (``"point"``, ``"cell"``, or None:
    the point array when the name is on the points, else the cell array)."""

    name: str
    component: Union[int, str, None] = None
    association: Optional[str] = None

    def __str__(self) -> str:
        where = "" if self.association is None else f"@{self.association}s"
        return f"{self.name}{where}" if self.component is None else f"{self.name}{where}:{self.component}"

    def matches(self, name: str, association: str) -> bool:
        """Whether this spec names the array ``name`` on ``association`` (a spec without one names either)."""
        return name == self.name and self.association in (None, association)


def _split_association(text: str) -> tuple[str, Optional[str]]:
    """``"p@cells"`` -> ("p", "cell"); a text without a trailing association word is kept whole."""
    name, sep, word = text.rpartition("@")
    where = ASSOCIATIONS.get(word.lower()) if sep and name else None
    return (name, where) if where is not None else (text, None)


def parse_array_spec(text: str) -> ArraySpec:
    """``"T"`` -> ArraySpec("T"), ``"V:1"`` -> component 1, ``"V:magnitude"`` (or ``"V:mag"``) -> the magnitude,
    ``"V@cells:1"`` (or ``"V:1@cells"``) -> component 1 of the cell array V. A name may itself hold colons and
    ``@``: only a trailing ``:digits`` or ``:magnitude`` is read as the component, and only ``@points`` / ``@cells``
    right before it (or at the end) as the association."""
    if not isinstance(text, str) or not text.strip():
        raise ValueError("an array spec is NAME, NAME:COMPONENT or NAME:magnitude (NAME@cells for a cell array of "
                         "a name also on the points), got an empty one")
    rest, association = _split_association(text)
    name, sep, tail = rest.rpartition(":")
    component: Union[int, str, None] = None
    if sep and name:
        if tail.isdigit():
            component = int(tail)
            if component >= MAX_COMPONENTS:
                raise ValueError(f"array spec {text!r}: component {component} is out of range 0..{MAX_COMPONENTS - 1}")
        elif tail.lower() in ("magnitude", "mag"):
            component = MAGNITUDE
    if component is None:
        name = rest
    if association is None:
        name, association = _split_association(name)
    return ArraySpec(name, component, association)


@dataclass
class ArrayInfo:
    """What ``list_arrays`` says of one array."""

    name: str
    association: str                   # "point" | "cell"
    components: int
    range: tuple[float, float]         # finite min and max of the scalar (of the magnitude for vectors)
    nonfinite: int                     # number of NaN / Inf values
    choices: list[str] = field(default_factory=list)

    @property
    def varies(self) -> bool:
        lo, hi = self.range
        return bool(np.isfinite(lo) and np.isfinite(hi) and hi > lo)


def _base(dataset: Any) -> Any:
    return dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset


def _arrays_of(dataset: Any) -> list[tuple[str, str, np.ndarray, int]]:
    """(name, association, values, n_components) of every array; values keep the dataset's layout."""
    d = _base(dataset)
    out: list[tuple[str, str, np.ndarray, int]] = []
    if isinstance(d, RegularVolume):
        arrays = d.arrays or {d.name: d.data}
        out += [(k, "point", v, 1 if v.ndim == 3 else int(v.shape[3])) for k, v in arrays.items()]
    elif isinstance(d, CurvilinearGrid):
        out += [(k, "point", v, 1 if v.ndim == 3 else int(v.shape[3])) for k, v in d.point_data.items()]
        out += [(k, "cell", v, 1 if v.ndim == 3 else int(v.shape[3])) for k, v in d.cell_data.items()]
    elif isinstance(d, UnstructuredMesh):
        out += [(k, "point", v, 1 if v.ndim == 1 else int(np.prod(v.shape[1:]))) for k, v in d.point_data.items()]
        out += [(k, "cell", v, 1 if v.ndim == 1 else int(np.prod(v.shape[1:]))) for k, v in d.cell_data.items()]
    elif isinstance(d, TetMesh):
        out.append((d.name, "point", d.scalars, 1))
    return [item for item in out if item[2].dtype.kind in "biuf"]


def _as_vectors(values: np.ndarray, association: str, n_components: int, dataset: Any) -> np.ndarray:
    """Values as (..., n_components) with the component axis last (scalars keep their shape)."""
    d = _base(dataset)
    spatial = 3 if isinstance(d, (RegularVolume, CurvilinearGrid)) else 1
    if n_components == 1 and values.ndim == spatial:
        return values
    return values.reshape(values.shape[:spatial] + (n_components,))


def _reduce(vectors: np.ndarray, spec: ArraySpec, n_components: int, spatial: int) -> np.ndarray:
    """One scalar per sample: the array itself, one component, or the magnitude (the default of vectors)."""
    if n_components == 1 and vectors.ndim == spatial:
        if spec.component not in (None, 0, MAGNITUDE):
            raise ValueError(f"array {spec.name!r} is a scalar array: it has no component {spec.component}")
        return vectors
    if spec.component is None or spec.component == MAGNITUDE:
        return np.linalg.norm(vectors.astype(np.float64), axis=-1)
    if not 0 <= int(spec.component) < n_components:
        raise ValueError(f"array {spec.name!r} has {n_components} components: component {spec.component} is out of "
                         f"range 0..{n_components - 1}")
    return np.ascontiguousarray(vectors[..., int(spec.component)])


def _finite_range(values: np.ndarray) -> tuple[tuple[float, float], int]:
    if values.dtype.kind not in "fc":
        return ((float(values.min()), float(values.max())) if values.size else (float("nan"),) * 2), 0
    finite = np.isfinite(values)
    bad = int(values.size - np.count_nonzero(finite))
    if bad == values.size:
        return (float("nan"), float("nan")), bad
    kept = values[finite] if bad else values
    return (float(kept.min()), float(kept.max())), bad


def list_arrays(dataset: Union[Dataset, TimeSeries]) -> list[ArrayInfo]:
    """Every numeric array of ``dataset`` (the first frame of a time series) with its range, number of non-finite
    values and the specs a user can choose for it."""
    d = _base(dataset)
    spatial = 3 if isinstance(d, (RegularVolume, CurvilinearGrid)) else 1
    arrays = _arrays_of(d)
    on_points = {name for name, association, _, _ in arrays if association == "point"}
    infos = []
    for name, association, values, n in arrays:
        vectors = _as_vectors(values, association, n, d)
        shown = _reduce(vectors, ArraySpec(name), n, spatial)
        rng, _ = _finite_range(shown)
        _, bad = _finite_range(values)
        where = "cell" if association == "cell" and name in on_points else None   # a plain name is the point array
        choices = [str(ArraySpec(name, c, where)) for c in ([None] if n == 1 else [MAGNITUDE, *range(n)])]
        infos.append(ArrayInfo(name, association, n, rng, bad, choices))
    return infos


def array_info(dataset: Union[Dataset, TimeSeries], spec: str) -> Optional[ArrayInfo]:
    """The ``list_arrays`` entry of the array ``spec`` names (its association's when it has one, else the point
    array's before the cell array's); None when the dataset has no such array."""
    parsed = parse_array_spec(spec)
    return next((i for i in list_arrays(dataset) if parsed.matches(i.name, i.association)), None)


#: names of arrays that describe how a surface looks rather than data on it: vertex normals (as PLY and VTK name
#: them), texture coordinates and vertex colours; compared in lower case without spaces and underscores
APPEARANCE_ARRAYS = frozenset({"nx", "ny", "nz", "normals", "tcoords", "texturecoordinates", "red", "green", "blue",
                               "alpha", "rgb", "rgba", "colors", "colours"})


def _plain_name(name: str) -> str:
    return name.lower().replace(" ", "").replace("_", "")


def is_appearance_array(name: str) -> bool:
    """Whether ``name`` is an appearance attribute (``APPEARANCE_ARRAYS``): never shown through a transfer function
    by default on a mesh; a surface with only these is drawn in its vertex colours, else in a plain colour."""
    return _plain_name(name) in APPEARANCE_ARRAYS


#: names of arrays that keep the books of a pipeline rather than measure anything: cell and point ids (original,
#: global, pedigree), block / object / process / file ids, ghost levels, validity masks; compared like
#: ``APPEARANCE_ARRAYS``
BOOKKEEPING_ARRAYS = frozenset({
    "vtkoriginalcellids", "vtkoriginalpointids", "vtkoriginalindices", "originalcellids", "originalpointids",
    "objectid", "globalnodeid", "globalelementid", "globalids", "globalpointids", "globalcellids",
    "pedigreeelementid", "pedigreenodeid", "pedigreeids", "vtkghosttype", "vtkghostlevels", "vtkcompositeindex",
    "elementblockids", "blockid", "blockids", "vtkblockcolors", "vtkprocessid", "processid", "fileid", "cellid",
    "pointid", "sourceelementid", "sourceelementside", "vtkvalidpointmask", "vtkinsidedness", "vtkpedigreeids"})


def is_bookkeeping_array(name: str) -> bool:
    """Whether ``name`` is a bookkeeping array (``BOOKKEEPING_ARRAYS``): ids, ghost levels, masks; never the default
    array while another exists, and on a mesh not at all (a mesh with nothing else is drawn plain)."""
    return _plain_name(name) in BOOKKEEPING_ARRAYS


def vertex_colors(dataset: object) -> np.ndarray | None:
    """The point colors of a surface (a mesh, or the PyVista data set drawn for it) as (n, 3) or (n, 4)
    uint8: its red, green, blue (and alpha) arrays, or one RGB / RGBA / colors array of 3 or 4 components; integers
    as bytes (meshio reads PLY's unsigned bytes as signed ones), floats in [0, 1] scaled to 255. None when it has
    none."""
    point_data = getattr(_base(dataset), "point_data", None) or {}
    named = {_plain_name(k): np.asarray(v) for k, v in point_data.items()}
    if all(k in named for k in ("red", "green", "blue")):
        parts = [named[k] for k in ("red", "green", "blue", "alpha") if k in named]
        if any(np.ndim(p) != 1 for p in parts):
            return None
        values = np.stack(parts, axis=1)
    else:
        found = [v for k, v in named.items() if k in ("rgb", "rgba", "colors", "colours")
                 and np.ndim(v) == 2 and np.shape(v)[1] in (3, 4)]
        if not found:
            return None
        values = found[0]
    values = np.asarray(values)
    if values.dtype.kind in "iu":
        return (values.astype(np.int64) % 256).astype(np.uint8)
    if values.dtype.kind == "f" and np.isfinite(values).all():
        scale = 255.0 if values.max(initial=0.0) <= 1.0 else 1.0
        return np.clip(np.rint(values * scale), 0, 255).astype(np.uint8)
    return None


def default_array(dataset: Union[Dataset, TimeSeries]) -> str | None:
    """The spec a first open shows: the dataset's active array when it varies, else the first point array that
    varies, else the first cell array that varies, else the first array (vectors by their magnitude). Bookkeeping
    arrays (``is_bookkeeping_array``: ids, ghost levels) are candidates only where nothing else is, and never on a
    mesh; on meshes appearance attributes (``is_appearance_array``) are not candidates either: None when nothing
    else is there, the mesh then drawn as plain geometry (``volviz.model.representation``; on a volume an "rgb"
    array is data: a colour microscopy stack)."""
    infos = list_arrays(dataset)
    base = _base(dataset)
    mesh = isinstance(base, UnstructuredMesh)
    if mesh:
        infos = [i for i in infos if not is_appearance_array(i.name)]
    if mesh or any(not is_bookkeeping_array(i.name) for i in infos):
        infos = [i for i in infos if not is_bookkeeping_array(i.name)]
    if not infos:
        return None
    active = getattr(_base(dataset), "active", None) or getattr(_base(dataset), "name", None)
    ordered = ([i for i in infos if i.name == active] + [i for i in infos if i.association == "point"]
               + [i for i in infos if i.association == "cell"])
    chosen = next((i for i in ordered if i.varies), ordered[0])
    return chosen.choices[0]


def scalar_of(arrays: dict[str, np.ndarray], spec: str) -> np.ndarray:
    """The (nx, ny, nz) scalar of ``spec`` among a regular volume's point arrays."""
    parsed = parse_array_spec(spec)
    if parsed.name not in arrays:
        raise ValueError(f"no array {parsed.name!r}; the volume has {', '.join(sorted(arrays))}")
    values = arrays[parsed.name]
    return _reduce(values, parsed, 1 if values.ndim == 3 else int(values.shape[3]), 3)


def volume_of(data: np.ndarray, name: str, spacing: tuple[float, float, float] = (1.0, 1.0, 1.0),
              origin: tuple[float, float, float] = (0.0, 0.0, 0.0), source: str = "") -> RegularVolume:
    """A regular volume of one point array ``data`` named ``name``: (nx, ny, nz) values, or (nx, ny, nz, c) with
    ``c`` > 1 components, then shown by its default array (``default_array``: the magnitude) and offered per
    component by the array selector."""
    if data.ndim == 4 and data.shape[3] == 1:
        data = data[..., 0]
    if data.ndim == 3:
        return RegularVolume(data, spacing=spacing, origin=origin, name=name, source=source)
    volume = RegularVolume(np.zeros(data.shape[:3], np.uint8), spacing=spacing, origin=origin, name=name,
                           source=source, arrays={name: data})
    spec = default_array(volume)
    assert spec is not None  # the volume has an array
    volume.data, volume.name = scalar_of(volume.arrays, spec), spec
    return volume


def _cell_to_point(dataset: Any, scalar: np.ndarray) -> np.ndarray:
    """A cell scalar averaged onto the points as VTK's cell-to-point filter does (as ParaView shows cell data): each
    point gets the mean of the cells that use it (a cell naming a point twice counts twice, as in VTK's cell links;
    a point no cell uses gets 0). NumPy, no VTK object: this runs on the app's worker threads, where making VTK
    objects can deadlock a render on the GUI thread (``volviz.jobs``)."""
    values = np.asarray(scalar, dtype=np.float64)
    if isinstance(dataset, CurvilinearGrid):
        return _structured_cell_to_point(values, dataset.dimensions)
    total = np.zeros(dataset.n_points)
    count = np.zeros(dataset.n_points)
    start = 0
    for _, conn in dataset.cells:
        if conn.size:
            per_cell = np.repeat(values[start:start + len(conn)], conn.shape[1])
            np.add.at(total, conn.ravel(), per_cell)
            np.add.at(count, conn.ravel(), 1.0)
        start += len(conn)
    return np.divide(total, count, out=np.zeros_like(total), where=count > 0)


def _structured_cell_to_point(cells: np.ndarray, dims: tuple[int, ...]) -> np.ndarray:
    """``_cell_to_point`` on a structured grid of ``dims`` points: each cell adds its value to its 2, 4 or 8 corner
    points (an axis of one point is flat: its cells have one corner along it)."""
    total = np.zeros(dims)
    count = np.zeros(dims)
    shifts = [(0, 1) if n > 1 else (0,) for n in dims]
    for di in shifts[0]:
        for dj in shifts[1]:
            for dk in shifts[2]:
                corner = tuple(slice(d, d + c) for d, c in zip((di, dj, dk), cells.shape[:3]))
                total[corner] += cells
                count[corner] += 1.0
    return total / count


@overload
def select_array(dataset: TimeSeries, spec: str | None) -> TimeSeries: ...


@overload
def select_array(dataset: Dataset, spec: str | None) -> Dataset: ...


def select_array(dataset: Union[Dataset, TimeSeries], spec: str | None) -> Union[Dataset, TimeSeries]:
    """``dataset`` showing the array ``spec`` (None: ``default_array``): a dataset of the same kind whose active
    point scalar is that array's scalar, component or magnitude, named by the spec. ValueError (naming the
    available arrays) when the dataset has no such array."""
    if isinstance(dataset, TimeSeries):
        chosen = spec if spec is not None else default_array(dataset)
        return TimeSeries(dataset.times, [None] * len(dataset), source=dataset.source,
                          loader=lambda i: select_array(dataset.frame(i), chosen))
    if spec is None:
        spec = default_array(dataset)
        if spec is None:
            return dataset
    parsed = parse_array_spec(spec)
    found = [(n, a, v, c) for n, a, v, c in _arrays_of(dataset) if parsed.matches(n, a)]
    if not found:
        names = ", ".join(str(replace(parse_array_spec(i.choices[0]), component=None))
                          for i in list_arrays(dataset)) or "none"
        what = "array" if parsed.association is None else f"{parsed.association} array"
        raise ValueError(f"no {what} {parsed.name!r}; the arrays are: {names}")
    name, association, values, n = found[0]
    spatial = 3 if isinstance(dataset, (RegularVolume, CurvilinearGrid)) else 1
    scalar = _reduce(_as_vectors(values, association, n, dataset), parsed, n, spatial)
    key = str(parsed)
    if isinstance(dataset, RegularVolume):
        return replace(dataset, data=scalar, name=key, arrays=dataset.arrays or {dataset.name: dataset.data})
    if isinstance(dataset, (TetMesh, Image2D)):   # (an image has no arrays: it does not come this far)
        return dataset
    cell_data = dataset.cell_data
    if association == "cell":   # shown at the points; the view keeps no cell array of the same name
        scalar = _cell_to_point(dataset, scalar)
        cell_data = {k: v for k, v in cell_data.items() if k != key}
    point_data = {**dataset.point_data, key: scalar}
    return replace(dataset, point_data=point_data, cell_data=cell_data, active=key)
