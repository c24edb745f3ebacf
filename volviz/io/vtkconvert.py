"""VTK data objects -> volviz model datasets (shared by the VTK legacy/XML and VTKHDF readers).

Every numeric point and cell array is kept. vtkImageData -> RegularVolume (``data`` is the active point scalars, else
the first array that varies, vectors by their magnitude; ``arrays`` holds every point array; cell-only images are
converted to point data by VTK's cell-to-point filter), vtkStructuredGrid and vtkRectilinearGrid -> CurvilinearGrid,
vtkUnstructuredGrid / vtkPolyData -> UnstructuredMesh (cells grouped by VTK type and size; cell data permuted to that
grouping). Composite data (multiblock, partitioned) is merged with vtkAppendFilter first. Float arrays are checked
for NaN/Inf (kept and counted by default).
"""
from __future__ import annotations

import warnings

import numpy as np

from volviz.io._checks import check_finite
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.io.vtk_lazy import vtk
from volviz.model import CELL_SIZES, CurvilinearGrid, RegularVolume, UnstructuredMesh
from volviz.model.arrays import default_array, scalar_of

_VTK_POLYHEDRON = 42
#: VTK's axis-aligned cells as the general ones, corners reordered: a voxel (11) is a hexahedron (12) and a pixel (8)
#: a quad (9) whose corners run x fastest instead of around the face (VTK's cell type documentation)
_AXIS_ALIGNED = {11: (12, np.array([0, 1, 3, 2, 4, 5, 7, 6])), 8: (9, np.array([0, 1, 3, 2]))}
# VTK's quadratic cell types with a linear counterpart: edge, triangle, quad, tetra, hexahedron, wedge, pyramid
_QUADRATIC = (21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32, 33)


def _arrays(path: PathLike, attributes, n: int, allow_nonfinite: bool, where: str,
            filled: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """The numeric arrays of ``n`` tuples, checked for NaN/Inf except where ``filled`` (name -> mask) says the merge
    put NaN for a block without the array (``_with_partial_arrays``)."""
    # heavy: VTK's numpy_support (vtkCommonCore), loaded only when a VTK dataset converts
    from vtkmodules.util.numpy_support import vtk_to_numpy

    out: dict[str, np.ndarray] = {}
    for i in range(attributes.GetNumberOfArrays()):
        arr = attributes.GetArray(i)  # None for string / non-numeric arrays
        if arr is None or arr.GetNumberOfTuples() != n:
            continue
        name = arr.GetName() or f"{where}{i}"
        values = np.array(vtk_to_numpy(arr))
        mask = (filled or {}).get(name)
        check_finite(path, values[~mask] if mask is not None and len(mask) == n else values, allow_nonfinite,
                     f"{where} array {name!r}")
        out[name] = values
    return out


def _active_name(attributes) -> str | None:
    scalars = attributes.GetScalars()
    return scalars.GetName() if scalars is not None and scalars.GetName() else None


def _attribute_sets(leaf) -> tuple:
    return ("point", leaf.GetPointData(), leaf.GetNumberOfPoints()), ("cell", leaf.GetCellData(),
                                                                         leaf.GetNumberOfCells())


_FILLED = "volviz filled "  # field data of a merged data set: where a partial array was filled, per element


def _filled(obj, where: str) -> dict[str, np.ndarray]:
    """The masks ``merge_composite`` left in ``obj``'s field data: array name -> True where it put NaN."""
    # heavy: VTK's numpy_support (vtkCommonCore), loaded only when a VTK dataset converts
    from vtkmodules.util.numpy_support import vtk_to_numpy

    fd, out = obj.GetFieldData(), {}
    for i in range(fd.GetNumberOfArrays()):
        name = fd.GetArrayName(i) or ""
        if name.startswith(_FILLED + where + ":"):
            out[name.split(":", 1)[1]] = vtk_to_numpy(fd.GetArray(i)).astype(bool)
    return out


def _with_partial_arrays(path: PathLike, leaves: list) -> tuple[list, dict[tuple[str, str], np.ndarray]]:
    """The blocks with every array that only some of them carry (an Exodus element variable defined on some element
    blocks) added to the others as NaN, as doubles in every block: vtkAppendFilter keeps only the arrays all its
    inputs share, and ParaView shows a partial array with NaN (no colour) where a block lacks it. A ReadWarning names
    them. Arrays whose component counts differ between blocks stay left out."""
    # heavy: VTK's numpy_support (vtkCommonCore), loaded only when a VTK dataset converts
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

    found: dict[tuple[str, str], list[int]] = {}
    for leaf in leaves:
        for where, attributes, _ in _attribute_sets(leaf):
            for i in range(attributes.GetNumberOfArrays()):
                arr = attributes.GetArray(i)
                if arr is not None and arr.GetName():
                    found.setdefault((where, arr.GetName()), []).append(arr.GetNumberOfComponents())
    partial = {key: comps[0] for key, comps in found.items() if len(comps) < len(leaves) and len(set(comps)) == 1}
    if not partial:
        return leaves, {}
    out: list = []
    masks: dict[tuple[str, str], list[np.ndarray]] = {key: [] for key in partial}
    for leaf in leaves:
        copy = leaf.NewInstance()
        copy.ShallowCopy(leaf)
        for where, attributes, n in _attribute_sets(copy):
            for (kind, name), comps in partial.items():
                if kind != where:
                    continue
                arr = attributes.GetArray(name)
                masks[(kind, name)].append(np.full(n, arr is None))
                values = (vtk_to_numpy(arr).astype(np.float64) if arr is not None
                          else np.full((n, comps) if comps > 1 else n, np.nan))
                doubles = numpy_to_vtk(np.ascontiguousarray(values), deep=True, array_type=vtk.VTK_DOUBLE)
                doubles.SetName(name)
                attributes.RemoveArray(name)
                attributes.AddArray(doubles)
        out.append(copy)
    names = ", ".join(f"{name} ({kind})" for kind, name in sorted(partial))
    warnings.warn(ReadWarning(f"{path}: {names}: defined on some of its {len(leaves)} blocks only; NaN (not drawn) "
                              "on the others"), stacklevel=4)
    return out, {key: np.concatenate(parts) for key, parts in masks.items()}


def merge_composite(path: PathLike, obj):
    """A composite data set (multiblock / partitioned) as one data set; ReadError if it holds nothing. Arrays only
    some blocks carry are kept, NaN elsewhere, with masks of the filled places in the field data (``_filled``)."""
    # heavy: VTK's numpy_support (vtkCommonCore), loaded only when a VTK dataset converts
    from vtkmodules.util.numpy_support import numpy_to_vtk

    if not obj.IsA("vtkCompositeDataSet"):
        return obj
    leaves = []
    it = obj.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        leaf = it.GetCurrentDataObject()
        if leaf is not None and leaf.IsA("vtkDataSet") and leaf.GetNumberOfPoints() > 0:
            leaves.append(leaf)
        it.GoToNextItem()
    if not leaves:
        raise ReadError(path, "holds no data set with points")
    if len(leaves) == 1:
        return leaves[0]
    leaves, masks = _with_partial_arrays(path, leaves)
    append = vtk.vtkAppendFilter()
    append.SetMergePoints(False)
    for leaf in leaves:
        append.AddInputData(leaf)
    append.Update()
    out = vtk.vtkUnstructuredGrid()
    out.ShallowCopy(append.GetOutput())
    for (where, name), mask in masks.items():
        flags = numpy_to_vtk(mask.astype(np.uint8), deep=True)
        flags.SetName(f"{_FILLED}{where}:{name}")
        out.GetFieldData().AddArray(flags)
    return out


def vtk_to_model(path: PathLike, obj, allow_nonfinite: bool = True):
    """Convert a VTK data object to the matching volviz model dataset.

    What the model refuses (zero spacing, connectivity outside the points, arrays of the wrong shape) comes out as
    a ReadError naming the file, never as the model's ValueError."""
    try:
        return _to_model(path, obj, allow_nonfinite)
    except (ValueError, IndexError, OverflowError) as exc:
        raise ReadError(path, f"the file's data set is inconsistent: {exc}") from None


def _to_model(path: PathLike, obj, allow_nonfinite: bool):
    # heavy: VTK's numpy_support (vtkCommonCore), loaded only when a VTK dataset converts
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if obj is None:
        raise ReadError(path, "the VTK reader produced no output")
    obj = merge_composite(path, obj)
    if not obj.IsA("vtkDataSet"):
        raise ReadError(path, f"holds a {obj.GetClassName()}, which volviz cannot use")
    n_points = obj.GetNumberOfPoints()
    if n_points == 0:
        raise ReadError(path, f"the {obj.GetClassName()} in the file has no points")
    pd = obj.GetPointData()
    if obj.IsA("vtkImageData"):
        return _image(path, obj, allow_nonfinite)
    if obj.IsA("vtkStructuredGrid") or obj.IsA("vtkRectilinearGrid"):
        ext = obj.GetExtent()
        dims = (ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1)
        if obj.IsA("vtkStructuredGrid"):
            pts = vtk_to_numpy(obj.GetPoints().GetData()).astype(np.float64)
        else:
            axes = [vtk_to_numpy(c).astype(np.float64) for c in (obj.GetXCoordinates(), obj.GetYCoordinates(),
                                                                  obj.GetZCoordinates())]
            grid = np.meshgrid(*axes, indexing="ij")
            pts = np.stack([g.ravel(order="F") for g in grid], axis=-1)
        check_finite(path, pts, False, "point coordinates")
        points = pts.reshape(tuple(dims) + (3,), order="F")
        arrays = _arrays(path, pd, n_points, allow_nonfinite, "point")
        point_data = {k: (v.reshape(dims, order="F") if v.ndim == 1
                          else v.reshape(tuple(dims) + v.shape[1:], order="F"))
                      for k, v in arrays.items()}
        cells = tuple(max(n - 1, 1) for n in dims)
        cell_data = {k: v.reshape(cells + v.shape[1:], order="F")
                     for k, v in _arrays(path, obj.GetCellData(), obj.GetNumberOfCells(), allow_nonfinite,
                                         "cell").items()}
        active = _active_name(pd)
        return CurvilinearGrid(points, point_data, active=active if active in point_data else None, source=str(path),
                               cell_data=cell_data)
    return _unstructured(path, obj, allow_nonfinite)


def _unstructured(path: PathLike, obj, allow_nonfinite: bool) -> UnstructuredMesh:
    # heavy: PyVista (about 200 modules), loaded only when a PyVista dataset converts
    import pyvista as pv

    grid = pv.wrap(obj)
    if not isinstance(grid, pv.UnstructuredGrid):
        grid = grid.cast_to_unstructured_grid()
    if np.any(np.isin(np.asarray(grid.celltypes), _QUADRATIC)):
        grid = grid.linear_copy()   # quadratic cells drawn through their corner nodes (PyVista's linear copy)
    points = np.asarray(grid.points, dtype=np.float64)
    check_finite(path, points, False, "point coordinates")
    types = np.asarray(grid.celltypes)
    if np.any(types == _VTK_POLYHEDRON):
        raise ReadError(path, "polyhedron cells (VTK type 42) are not supported")
    offsets = np.asarray(grid.cell_offsets if hasattr(grid, "cell_offsets") else grid.offset, dtype=np.int64)
    conn = np.asarray(grid.cell_connectivity, dtype=np.int64)
    sizes = np.diff(offsets)
    cells, order = [], []
    keys = np.stack([types.astype(np.int64), sizes], axis=1) if len(types) else np.empty((0, 2), np.int64)
    for ctype, size in sorted({(int(t), int(s)) for t, s in keys}):
        idx = np.flatnonzero((types == ctype) & (sizes == size))
        block = conn[(offsets[idx][:, None] + np.arange(size)[None, :])] if size else np.empty((len(idx), 0), np.int64)
        if ctype in _AXIS_ALIGNED and size == len(_AXIS_ALIGNED[ctype][1]):
            ctype, corner_order = _AXIS_ALIGNED[ctype]
            block = block[:, corner_order]
        corners = CELL_SIZES.get(ctype, size)
        cells.append((ctype, block[:, :corners] if size > corners else block))
        order.append(idx)
    perm = np.concatenate(order) if order else np.empty(0, np.int64)
    pd, cd = obj.GetPointData(), obj.GetCellData()
    point_data = _arrays(path, pd, obj.GetNumberOfPoints(), allow_nonfinite, "point", _filled(obj, "point"))
    cell_data = {k: v[perm] for k, v in _arrays(path, cd, obj.GetNumberOfCells(), allow_nonfinite, "cell",
                                                _filled(obj, "cell")).items()}
    active = _active_name(pd)
    return UnstructuredMesh(points, cells, point_data, cell_data,
                            active=active if active in point_data else None, source=str(path))


def _image(path: PathLike, obj, allow_nonfinite: bool) -> RegularVolume:
    """vtkImageData -> RegularVolume keeping every point array (cell arrays through VTK's cell-to-point filter)."""
    if obj.GetPointData().GetNumberOfArrays() == 0 and obj.GetCellData().GetNumberOfArrays() > 0:
        to_points = vtk.vtkCellDataToPointData()
        to_points.SetInputData(obj)
        to_points.Update()
        obj = to_points.GetOutput()
    pd = obj.GetPointData()
    dims = tuple(obj.GetDimensions())
    arrays = {k: v.reshape(dims + v.shape[1:], order="F")
              for k, v in _arrays(path, pd, obj.GetNumberOfPoints(), allow_nonfinite, "point").items()}
    if not arrays:
        raise ReadError(path, "image data without numeric point or cell data arrays")
    direction = np.array([obj.GetDirectionMatrix().GetElement(i, j) for i in range(3) for j in range(3)])
    if not np.allclose(direction, np.eye(3).ravel()):
        warnings.warn(f"{path}: image direction matrix {direction.tolist()} is ignored (volumes are "
                      "axis-aligned)", ReadWarning, stacklevel=3)
    for what, values in (("origin", obj.GetOrigin()), ("spacing", obj.GetSpacing())):
        if not np.all(np.isfinite(values)):
            raise ReadError(path, f"image {what} {tuple(values)} is not finite")
    volume = RegularVolume(np.zeros(dims, np.uint8), spacing=obj.GetSpacing(), origin=obj.GetOrigin(),
                           source=str(path), arrays=arrays)
    active = _active_name(pd)
    spec = active if active in arrays and arrays[active].ndim == 3 else default_array(volume)
    assert spec is not None  # the volume has arrays
    volume.data, volume.name = scalar_of(arrays, spec), spec
    return volume
