"""Typed datasets that every reader returns and every renderer consumes.

Conventions (used everywhere in volviz):

- Regular volumes store their samples as ``data[i, j, k]`` with ``i`` along x, ``j`` along y and ``k`` along z, i.e.
  shape ``(nx, ny, nz)``. Flattening in Fortran order gives VTK's point order (x fastest).
- 2D images (height fields, fog maps, textures) store ``data[row, col]`` with row 0 at the top of the file as read
  (north for maps and DEMs), and an optional trailing channel axis. ``origin`` is the position of the bottom-left
  (south-west) sample, as in VTK, so row ``r`` lies at ``y = origin_y + (rows - 1 - r) * spacing_y``.
- Every coordinate is float64; scalar arrays keep their file's dtype until a renderer converts them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Iterable, Union

import numpy as np

if TYPE_CHECKING:   # type-only: PyVista loads VTK, which the model does not need at run time
    import pyvista as pv

# VTK cell type ids for the cell blocks of UnstructuredMesh (subset used by volviz).
VTK_TETRA = 10
VTK_HEXAHEDRON = 12
VTK_WEDGE = 13
VTK_PYRAMID = 14
VTK_TRIANGLE = 5
VTK_QUAD = 9
VTK_VERTEX = 1
CELL_SIZES = {VTK_TETRA: 4, VTK_HEXAHEDRON: 8, VTK_WEDGE: 6, VTK_PYRAMID: 5, VTK_TRIANGLE: 3, VTK_QUAD: 4}


def vec3(value: Iterable[float], name: str = "vector") -> tuple[float, float, float]:
    """Three numbers as a tuple of three floats; ValueError naming ``name`` for another count."""
    vec = tuple(float(v) for v in value)
    if len(vec) != 3:
        raise ValueError(f"{name} must have three components, got {len(vec)}")
    return vec


def _range(values: np.ndarray) -> tuple[float, float]:
    finite = values[np.isfinite(values)] if values.dtype.kind == "f" else values
    if finite.size == 0:
        return (float("nan"), float("nan"))
    return (float(finite.min()), float(finite.max()))


@dataclass
class RegularVolume:
    """Scalar samples on a uniform grid (Guthe Ch. 2 volumes, SLC, PVM, MHD, raw, VTK image data)."""

    data: np.ndarray
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str = "scalars"
    source: str = ""
    arrays: dict[str, np.ndarray] = field(default_factory=dict)  # every point array of the file, by name

    def __post_init__(self) -> None:
        if self.data.ndim != 3:
            raise ValueError(f"RegularVolume data must be 3D (nx, ny, nz), got shape {self.data.shape}")
        if min(self.data.shape) < 1:
            raise ValueError(f"RegularVolume dimensions must be positive, got {self.data.shape}")
        self.spacing = vec3(self.spacing, "spacing")
        self.origin = vec3(self.origin, "origin")
        if min(self.spacing) <= 0 or not all(np.isfinite(self.spacing)):
            raise ValueError(f"RegularVolume spacing must be positive and finite, got {self.spacing}")
        for name, arr in self.arrays.items():
            if arr.shape[:3] != self.data.shape:
                raise ValueError(f"point array {name!r} has shape {arr.shape}, volume is {self.data.shape}")

    kind = "regular volume"

    @property
    def dimensions(self) -> tuple[int, int, int]:
        return tuple(int(n) for n in self.data.shape)  # type: ignore[return-value]

    @property
    def n_points(self) -> int:
        return int(self.data.size)

    @property
    def n_cells(self) -> int:
        return int(np.prod([max(n - 1, 1) for n in self.data.shape]))

    def scalar_range(self) -> tuple[float, float]:
        return _range(self.data)

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        lo = np.asarray(self.origin)
        hi = lo + (np.asarray(self.data.shape) - 1) * np.asarray(self.spacing)
        return (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])

    def to_pyvista(self) -> pv.ImageData:
        # PyVista (VTK, heavy): the model stays VTK-free until a PyVista form is asked for
        import pyvista as pv

        grid = pv.ImageData(dimensions=self.data.shape, spacing=self.spacing, origin=self.origin)
        grid.point_data[self.name] = self.data.ravel(order="F")
        grid.set_active_scalars(self.name)
        return grid


@dataclass
class CurvilinearGrid:
    """A structured grid with explicit point coordinates (PLOT3D), ``points`` of shape (nx, ny, nz, 3)."""

    points: np.ndarray
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    active: str | None = None
    source: str = ""
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)  # (nx-1, ny-1, nz-1[, c]) per array

    kind = "curvilinear grid"

    def __post_init__(self) -> None:
        if self.points.ndim != 4 or self.points.shape[3] != 3:
            raise ValueError(f"CurvilinearGrid points must have shape (nx, ny, nz, 3), got {self.points.shape}")
        for name, arr in self.point_data.items():
            if arr.shape[:3] != self.points.shape[:3]:
                raise ValueError(f"point array {name!r} has shape {arr.shape}, grid is {self.points.shape[:3]}")
        cells = tuple(max(n - 1, 1) for n in self.points.shape[:3])
        for name, arr in self.cell_data.items():
            if arr.shape[:3] != cells:
                raise ValueError(f"cell array {name!r} has shape {arr.shape}, grid has {cells} cells")
        if self.active is None and self.point_data:
            self.active = next(iter(self.point_data))

    @property
    def dimensions(self) -> tuple[int, int, int]:
        return tuple(int(n) for n in self.points.shape[:3])  # type: ignore[return-value]

    @property
    def n_points(self) -> int:
        return int(np.prod(self.points.shape[:3]))

    @property
    def n_cells(self) -> int:
        return int(np.prod([max(n - 1, 1) for n in self.points.shape[:3]]))

    def scalar_range(self, name: str | None = None) -> tuple[float, float]:
        name = name or self.active
        return _range(self.point_data[name]) if name else (float("nan"), float("nan"))

    def to_pyvista(self) -> pv.StructuredGrid:
        # PyVista (VTK, heavy): only for the PyVista form
        import pyvista as pv

        nx, ny, nz = self.dimensions
        grid = pv.StructuredGrid()
        grid.points = self.points.reshape(-1, 3, order="F")
        grid.dimensions = (nx, ny, nz)
        for name, arr in self.point_data.items():
            if arr.ndim == 3:
                grid.point_data[name] = arr.ravel(order="F")
            else:
                grid.point_data[name] = arr.reshape(-1, arr.shape[-1], order="F")
        for name, arr in self.cell_data.items():
            n = int(np.prod(arr.shape[:3]))
            grid.cell_data[name] = arr.reshape((n,) + arr.shape[3:], order="F")
        if self.active:
            grid.set_active_scalars(self.active)
        return grid


@dataclass
class UnstructuredMesh:
    """Points plus blocks of cells of one VTK type each (tetrahedra, hexahedra, wedges, pyramids, ...)."""

    points: np.ndarray
    cells: list[tuple[int, np.ndarray]]
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)
    active: str | None = None
    source: str = ""

    kind = "unstructured mesh"

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=np.float64)
        if self.points.ndim != 2 or self.points.shape[1] != 3:
            raise ValueError(f"mesh points must have shape (n, 3), got {self.points.shape}")
        n = len(self.points)
        if n and not any(len(conn) for _, conn in self.cells) and not any(len(a) for a in self.cell_data.values()):
            # points without cells (a PLY or VTK file of vertices only): a point cloud, one vertex cell per point
            self.cells = [(VTK_VERTEX, np.arange(n, dtype=np.int64).reshape(-1, 1))]
            self.cell_data = {}
        for cell_type, conn in self.cells:
            if conn.ndim != 2:
                raise ValueError(f"cell block of type {cell_type} must be 2D, got shape {conn.shape}")
            if conn.size and (conn.min() < 0 or conn.max() >= n):
                raise ValueError(f"cell block of type {cell_type} refers to points outside 0..{n - 1}")
        if self.active is None and self.point_data:
            self.active = next(iter(self.point_data))

    @property
    def n_points(self) -> int:
        return int(len(self.points))

    @property
    def n_cells(self) -> int:
        return int(sum(len(conn) for _, conn in self.cells))

    @property
    def dimensions(self) -> tuple[int, ...]:
        return (self.n_points, self.n_cells)

    def scalar_range(self, name: str | None = None) -> tuple[float, float]:
        name = name or self.active
        return _range(self.point_data[name]) if name else (float("nan"), float("nan"))

    def to_pyvista(self) -> pv.UnstructuredGrid:
        # PyVista (VTK, heavy): only for the PyVista form
        import pyvista as pv

        cells = {int(t): np.asarray(c, dtype=np.int64) for t, c in self.cells}
        grid = pv.UnstructuredGrid(cells, self.points)
        for name, arr in self.point_data.items():
            grid.point_data[name] = arr
        for name, arr in self.cell_data.items():
            grid.cell_data[name] = arr
        if self.active:
            grid.set_active_scalars(self.active)
        return grid


@dataclass
class TetMesh:
    """A conforming tetrahedral mesh with one scalar per point: the input of every unstructured renderer."""

    points: np.ndarray
    tets: np.ndarray
    scalars: np.ndarray
    name: str = "scalars"
    source: str = ""

    kind = "tetrahedral mesh"

    def __post_init__(self) -> None:
        self.points = np.ascontiguousarray(self.points, dtype=np.float64)
        self.tets = np.ascontiguousarray(self.tets, dtype=np.int64)
        self.scalars = np.ascontiguousarray(self.scalars, dtype=np.float64)
        if self.points.ndim != 2 or self.points.shape[1] != 3:
            raise ValueError(f"TetMesh points must have shape (n, 3), got {self.points.shape}")
        if self.tets.ndim != 2 or self.tets.shape[1] != 4:
            raise ValueError(f"TetMesh tets must have shape (m, 4), got {self.tets.shape}")
        if self.scalars.shape != (len(self.points),):
            raise ValueError(f"TetMesh needs one scalar per point: {self.scalars.shape} for {len(self.points)} points")
        if self.tets.size and (self.tets.min() < 0 or self.tets.max() >= len(self.points)):
            raise ValueError("TetMesh tets refer to points outside the point array")

    @property
    def n_points(self) -> int:
        return int(len(self.points))

    @property
    def n_cells(self) -> int:
        return int(len(self.tets))

    @property
    def dimensions(self) -> tuple[int, ...]:
        return (self.n_points, self.n_cells)

    def scalar_range(self) -> tuple[float, float]:
        return _range(self.scalars)

    def to_pyvista(self) -> pv.UnstructuredGrid:
        # PyVista (VTK, heavy): only for the PyVista form
        import pyvista as pv

        grid = pv.UnstructuredGrid({VTK_TETRA: self.tets}, self.points)
        grid.point_data[self.name] = self.scalars
        grid.set_active_scalars(self.name)
        return grid


@dataclass
class Image2D:
    """A 2D raster: height field, fog map or color texture (PGM/PPM/DEM). ``data`` is (rows, cols[, channels])."""

    data: np.ndarray
    spacing: tuple[float, float] = (1.0, 1.0)
    origin: tuple[float, float] = (0.0, 0.0)
    maxval: int | None = None
    source: str = ""

    kind = "image"

    def __post_init__(self) -> None:
        if self.data.ndim not in (2, 3):
            raise ValueError(f"Image2D data must be (rows, cols) or (rows, cols, channels), got {self.data.shape}")
        self.spacing = (float(self.spacing[0]), float(self.spacing[1]))
        self.origin = (float(self.origin[0]), float(self.origin[1]))

    @property
    def dimensions(self) -> tuple[int, ...]:
        return tuple(int(n) for n in self.data.shape)

    @property
    def n_points(self) -> int:
        return int(self.data.shape[0] * self.data.shape[1])

    @property
    def n_cells(self) -> int:
        return int(max(self.data.shape[0] - 1, 1) * max(self.data.shape[1] - 1, 1))

    @property
    def channels(self) -> int:
        return 1 if self.data.ndim == 2 else int(self.data.shape[2])

    def scalar_range(self) -> tuple[float, float]:
        return _range(self.data)

    def to_pyvista(self) -> pv.ImageData:
        """Image data on the z = 0 plane, x along columns, y northwards (row 0, the top row, at the largest y)."""
        # PyVista (VTK, heavy): only for the PyVista form
        import pyvista as pv

        rows, cols = self.data.shape[:2]
        grid = pv.ImageData(dimensions=(cols, rows, 1), spacing=(self.spacing[0], self.spacing[1], 1.0),
                            origin=(self.origin[0], self.origin[1], 0.0))
        flipped = self.data[::-1]  # VTK's first row is the bottom (southern) one
        values = flipped.reshape(rows * cols, -1) if self.data.ndim == 3 else flipped.reshape(-1)
        grid.point_data["values"] = values
        return grid


Dataset = Union[RegularVolume, CurvilinearGrid, UnstructuredMesh, TetMesh, Image2D]


@dataclass
class TimeSeries:
    """A sequence of datasets of one kind at increasing times; frames load lazily through ``loader`` if given."""

    times: np.ndarray
    frames: list[Dataset | None]
    loader: Callable[[int], Dataset] | None = None
    source: str = ""

    kind = "time series"

    def __post_init__(self) -> None:
        self.times = np.asarray(self.times, dtype=np.float64)
        if self.times.ndim != 1 or len(self.times) != len(self.frames):
            raise ValueError(f"TimeSeries needs one time per frame: {self.times.shape} times, "
                             f"{len(self.frames)} frames")
        if len(self.times) == 0:
            raise ValueError("TimeSeries needs at least one frame")
        if np.any(np.diff(self.times) <= 0):
            raise ValueError("TimeSeries times must increase strictly")

    def __len__(self) -> int:
        return len(self.frames)

    def frame(self, index: int) -> Dataset:
        item = self.frames[index]
        if item is None:
            if self.loader is None:
                raise ValueError(f"frame {index} is not loaded and the series has no loader")
            item = self.loader(index)
            self.frames[index] = item
        return item

    @property
    def n_steps(self) -> int:
        return len(self.frames)

    @property
    def dimensions(self) -> tuple[int, ...]:
        return self.frame(0).dimensions

    @property
    def n_points(self) -> int:
        return self.frame(0).n_points

    @property
    def n_cells(self) -> int:
        return self.frame(0).n_cells

    def scalar_range(self) -> tuple[float, float]:
        lo, hi = np.inf, -np.inf
        for i in range(len(self)):
            a, b = self.frame(i).scalar_range()
            if np.isfinite(a):
                lo, hi = min(lo, a), max(hi, b)
        return (float(lo), float(hi)) if np.isfinite(lo) else (float("nan"), float("nan"))

    def to_pyvista(self) -> pv.DataSet:
        return self.frame(0).to_pyvista()
