"""Checks of a VTKHDF file's structure with h5py before ``vtkHDFReader`` sees it.

vtkHDFReader trusts the counts a file stores (``NumberOfCells`` -1, ``NumberOfParts`` 1e9) and indexes its
datasets with them; a lie crashes or aborts it. Here only metadata and the small count datasets are read:

- no dataset claims more bytes than the file could hold after decompression;
- every count dataset (``NumberOfPoints``, ``NumberOfCells``, ``NumberOfConnectivityIds`` and, for transient
  files, ``Steps/NumberOfParts``, ``PartOffsets``, ``PointOffsets``, ``CellOffsets``, ``ConnectivityIdOffsets`` and
  the data offsets) is one- or two-dimensional, of integers, not negative and short enough to read;
- the counts agree with the datasets they describe: a static file's ``Points``, ``Types``, ``Offsets``,
  ``Connectivity`` and point and cell arrays have exactly the rows its counts add up to; each step of a transient
  file stays inside them;
- an image's ``WholeExtent`` has ordered bounds, ``Origin`` and ``Spacing`` are finite, its arrays hold at least
  the points (cells) of the extent;
- composite files (multiblock, partitioned collections) are checked block by block.
"""
from __future__ import annotations

from typing import NoReturn

import numpy as np

from volviz.io.errors import PathLike, ReadError, bytes_and_size

TYPES = ("ImageData", "UnstructuredGrid", "PolyData", "OverlappingAMR", "MultiBlockDataSet",
         "PartitionedDataSetCollection", "HyperTreeGrid")
TOPOLOGIES = ("Vertices", "Lines", "Polygons", "Strips")
DEFLATE_BUDGET = 1100  # bytes a dataset may claim per byte of file: deflate expands at most ~1032:1


def check_dataset_sizes(path: PathLike, root, size: int) -> None:
    """No dataset may claim more bytes than the file could hold after decompression, so a corrupt shape cannot
    make VTK allocate a huge array."""
    # heavy: h5py (about 45 modules), loaded only when a VTKHDF file is checked
    import h5py

    budget = DEFLATE_BUDGET * size + (1 << 20)
    found: list[tuple[str, int]] = []

    def visit(name: str, obj) -> None:
        if isinstance(obj, h5py.Dataset):
            found.append((name, int(np.prod(obj.shape or (), dtype=object)) * obj.dtype.itemsize))  # None: empty

    root.visititems(visit)
    prefix = root.name.rstrip("/")  # "/VTKHDF", or "" for a whole file
    for name, nbytes in found:
        if nbytes > budget:
            raise ReadError(path, f"dataset {prefix}/{name} claims {nbytes} bytes, more than the file's {size} bytes "
                                  "can hold even compressed")


class _Structure:
    """The checks of one VTKHDF data set group (the root, or one block of a composite file)."""

    def __init__(self, path: PathLike, group, size: int, where: str) -> None:
        self.path, self.group, self.size, self.where = path, group, size, where

    def fail(self, problem: str) -> NoReturn:
        raise ReadError(self.path, f"VTKHDF {problem}")

    def rows(self, name: str, group=None) -> int:
        """The first dimension of dataset ``name`` (ReadError when it is missing)."""
        group = self.group if group is None else group
        if name not in group:
            self.fail(f"{self.where}/{name} is missing")
        shape = group[name].shape
        return int(shape[0]) if shape else 1

    def counts(self, name: str, group=None, ndim: tuple[int, ...] = (1,)) -> np.ndarray:
        """A small integer count dataset, read after its shape and type are checked; never negative."""
        # heavy: h5py (about 45 modules), loaded only when a VTKHDF file is checked
        import h5py

        group = self.group if group is None else group
        label = f"{self.where}/{name}" if group is self.group else f"{group.name}/{name}"
        if name not in group or not isinstance(group[name], h5py.Dataset):
            self.fail(f"{label} is missing")
        ds = group[name]
        if ds.ndim not in ndim or ds.dtype.kind not in "iu":
            self.fail(f"{label} has shape {ds.shape} of {ds.dtype}, not {' or '.join(map(str, ndim))}-dimensional "
                      "integers")
        if ds.size > self.size:
            self.fail(f"{label} holds {ds.size} counts, more than the file's {self.size} bytes can hold")
        values = np.asarray(ds[()])
        if values.size and values.min() < 0:
            self.fail(f"{label} holds a negative count ({int(values.min())})")
        if values.size and float(values.max()) > DEFLATE_BUDGET * self.size:
            self.fail(f"{label} holds the count {float(values.max()):.0f}, more than the file's "
                      f"{bytes_and_size(self.size)} can describe")
        return values.astype(np.int64)

    def agree(self, label: str, rows: int, expected: int) -> None:
        if rows != expected:
            self.fail(f"{self.where}/{label} has {rows} rows, but the counts add up to {expected}")

    # -- kinds ----------------------------------------------------------------------------------------------------
    def check(self, kind: str) -> None:
        if kind not in TYPES:
            self.fail(f"{self.where} has a Type that is not one of {', '.join(TYPES)}")
        if kind == "ImageData":
            self.image()
        elif kind in ("UnstructuredGrid", "PolyData"):
            self.mesh(kind)
        elif kind in ("MultiBlockDataSet", "PartitionedDataSetCollection"):
            self.blocks()

    def image(self) -> None:
        attrs = self.group.attrs
        extent = np.asarray(attrs.get("WholeExtent", []))
        if extent.shape != (6,) or extent.dtype.kind not in "iu":
            self.fail(f"{self.where} WholeExtent is not six integers")
        lo, hi = extent[0::2].astype(np.int64), extent[1::2].astype(np.int64)
        if np.any(lo > hi):
            self.fail(f"{self.where} WholeExtent {extent.tolist()} has a lower bound above its upper bound")
        for key in ("Origin", "Spacing"):
            if key in attrs:
                values = np.asarray(attrs[key], dtype=np.float64).ravel()
                if values.size != 3 or not np.isfinite(values).all():
                    self.fail(f"{self.where} {key} is not three finite numbers")
        dims = (hi - lo + 1).tolist()
        points = int(np.prod(dims, dtype=object))
        cells = int(np.prod([max(d - 1, 1) for d in dims], dtype=object))
        for section, needed in (("PointData", points), ("CellData", cells)):
            for name, ds in self.arrays(section):
                if ds.size < needed:
                    self.fail(f"{self.where}/{section}/{name} holds {ds.size} values, fewer than the "
                              f"{needed} of the WholeExtent {extent.tolist()}")

    def arrays(self, section: str):
        # heavy: h5py (about 45 modules), loaded only when a VTKHDF file is checked
        import h5py

        if section not in self.group:
            return []
        return [(k, v) for k, v in self.group[section].items() if isinstance(v, h5py.Dataset)]

    def mesh(self, kind: str) -> None:
        n_points = self.counts("NumberOfPoints")
        parts = len(n_points)
        if kind == "UnstructuredGrid":
            topologies = {"": self.group}
        else:
            topologies = {t: self.group[t] for t in TOPOLOGIES if t in self.group}
        cells, ids = {}, {}
        for name, group in topologies.items():
            cells[name], ids[name] = self.counts("NumberOfCells", group), self.counts("NumberOfConnectivityIds", group)
            for label, values in (("NumberOfCells", cells[name]), ("NumberOfConnectivityIds", ids[name])):
                if len(values) != parts:
                    self.fail(f"{self.where}/{name + '/' if name else ''}{label} has {len(values)} entries, "
                              f"NumberOfPoints {parts}")
            # connectivity ids index the part's points: a part (a time step's) with ids has points
            empty = np.flatnonzero((ids[name] > 0) & (n_points == 0))
            if len(empty):
                self.fail(f"{self.where}/NumberOfPoints entry {int(empty[0])} is 0, but that part's "
                          f"{name + '/' if name else ''}cells connect {int(ids[name][empty[0]])} point ids")
        if "Steps" in self.group:
            self.steps(n_points, topologies, cells, ids)
            return
        self.agree("Points", self.rows("Points"), int(n_points.sum()))
        for name, group in topologies.items():
            prefix = f"{name}/" if name else ""
            total = int(cells[name].sum())
            if kind == "UnstructuredGrid":
                self.agree("Types", self.rows("Types"), total)
            self.agree(prefix + "Offsets", self.rows("Offsets", group), total + parts)
            self.agree(prefix + "Connectivity", self.rows("Connectivity", group), int(ids[name].sum()))

    def steps(self, n_points: np.ndarray, topologies: dict, cells: dict, ids: dict) -> None:
        """Each step's parts, points, cells and connectivity stay inside the datasets they index."""
        steps = self.group["Steps"]
        n = self.rows("Values", steps)
        parts = self.counts("NumberOfParts", steps)
        first = self.counts("PartOffsets", steps)
        point_offsets = self.counts("PointOffsets", steps)
        for label, values in (("NumberOfParts", parts), ("PartOffsets", first), ("PointOffsets", point_offsets)):
            if len(values) != n:
                self.fail(f"{self.where}/Steps/{label} has {len(values)} entries for {n} steps")
        if np.any(first + parts > len(n_points)):
            s = int(np.argmax(first + parts > len(n_points)))
            self.fail(f"{self.where}/Steps: step {s} uses parts {first[s]} to {first[s] + parts[s] - 1}, but the "
                      f"file describes {len(n_points)} parts")

        def per_step(values: np.ndarray) -> np.ndarray:
            total = np.concatenate(([0], np.cumsum(values)))
            return total[first + parts] - total[first]

        self.inside("Points", point_offsets + per_step(n_points), self.rows("Points"))
        if "CellOffsets" not in steps or "ConnectivityIdOffsets" not in steps:
            return
        cell_offsets = self.counts("CellOffsets", steps, ndim=(1, 2)).reshape(n, -1)
        id_offsets = self.counts("ConnectivityIdOffsets", steps, ndim=(1, 2)).reshape(n, -1)
        for t, (name, group) in enumerate(topologies.items()):
            if cell_offsets.shape[1] <= t or id_offsets.shape[1] <= t:
                self.fail(f"{self.where}/Steps/CellOffsets has shape {cell_offsets.shape} for {n} steps and "
                          f"{len(topologies)} cell kinds")
            prefix = f"{name}/" if name else ""
            step_cells = per_step(cells[name])
            self.inside(prefix + "Offsets", cell_offsets[:, t] + step_cells + parts, self.rows("Offsets", group))
            self.inside(prefix + "Connectivity", id_offsets[:, t] + per_step(ids[name]),
                        self.rows("Connectivity", group))

    def inside(self, label: str, ends: np.ndarray, rows: int) -> None:
        if ends.size and int(ends.max()) > rows:
            s = int(np.argmax(ends))
            self.fail(f"{self.where}/{label}: step {s} reaches row {int(ends[s])}, but it has {rows} rows")

    def blocks(self) -> None:
        # heavy: h5py (about 45 modules), loaded only when a VTKHDF file is checked
        import h5py

        for name, child in self.group.items():
            if isinstance(child, h5py.Group) and "Type" in child.attrs:
                _Structure(self.path, child, self.size, f"{self.where}/{name}").check(type_of(child))


def type_of(group) -> str:
    kind = group.attrs.get("Type")
    if kind is None:
        return ""
    return kind.decode("utf-8", "replace") if isinstance(kind, bytes) else str(kind)


def check_structure(path: PathLike, root, size: int) -> str:
    """Check the /VTKHDF group (see the module docstring); returns its data set type."""
    kind = type_of(root)
    if not kind:
        raise ReadError(path, "/VTKHDF has no Type attribute")
    check_dataset_sizes(path, root, size)
    _Structure(path, root, size, "/VTKHDF").check(kind)
    return kind
