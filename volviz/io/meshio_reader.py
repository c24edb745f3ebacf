"""Any mesh format meshio reads (Gmsh .msh, Abaqus .inp, Exodus, MED, XDMF, OFF, STL, ...) -> UnstructuredMesh.

meshio's exceptions (of any type: its format readers raise what they like) become ReadError naming the file.
Cell blocks keep meshio's order; their types are mapped to VTK type ids. Point and cell data of numeric type are
kept; float data is checked for NaN/Inf.
"""
from __future__ import annotations

import contextlib
import io

import numpy as np

from volviz.io._checks import check_file, check_finite, open_file
from volviz.io.errors import PathLike, ReadError
from volviz.model import UnstructuredMesh


def meshio_extensions() -> list[str]:
    # heavy: meshio (about 180 modules), loaded only when a meshio format is read
    import meshio

    return sorted(meshio.extension_to_filetypes)


def read_meshio(path: PathLike, file_format: str | None = None, allow_nonfinite: bool = True) -> UnstructuredMesh:
    """Read a mesh with meshio and convert it (cells as VTK type ids)."""
    # heavy: meshio (about 180 modules), loaded only when a meshio format is read
    import meshio
    from meshio._vtk_common import meshio_to_vtk_type

    check_file(path)
    open_file(path).close()  # permission problems as ReadError before meshio sees the file
    chatter = io.StringIO()
    try:
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            mesh = meshio.read(path, file_format=file_format)
    except ReadError:
        raise
    except MemoryError:
        raise ReadError(path, "meshio ran out of memory: the file's header claims an impossible size") from None
    except SystemExit:  # meshio calls sys.exit(1) when several candidate formats all fail
        detail = " ".join(chatter.getvalue().split())[:200]
        raise ReadError(path, f"meshio could not read it ({detail or 'no reader accepted the file'})") from None
    except Exception as exc:  # meshio's readers raise many exception types for bad input
        raise ReadError(path, f"meshio could not read it ({type(exc).__name__}: {str(exc)[:200]})") from None
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise ReadError(path, f"mesh points have shape {points.shape}, expected (n, 2) or (n, 3)")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    check_finite(path, points, False, "point coordinates")
    cells = []
    keep = []
    for i, block in enumerate(mesh.cells):
        vtk_type = meshio_to_vtk_type.get(block.type)
        data = np.asarray(block.data)
        if vtk_type is None or data.ndim != 2:
            raise ReadError(path, f"cell type {block.type!r} is not supported (no fixed-size VTK equivalent)")
        if data.size and (data.min() < 0 or data.max() >= len(points)):
            raise ReadError(path, f"{block.type} cells refer to points outside 0..{len(points) - 1}")
        cells.append((int(vtk_type), data.astype(np.int64)))
        keep.append(i)
    point_data = {}
    for name, values in mesh.point_data.items():
        arr = np.asarray(values)
        if arr.dtype.kind in "uif" and len(arr) == len(points):
            check_finite(path, arr, allow_nonfinite, f"point array {name!r}")
            point_data[name] = arr
    cell_data = {}
    for name, blocks in mesh.cell_data.items():
        arrays = [np.asarray(blocks[i]) for i in keep]
        if arrays and all(a.dtype.kind in "uif" for a in arrays):
            arr = np.concatenate(arrays)
            check_finite(path, arr, allow_nonfinite, f"cell array {name!r}")
            cell_data[name] = arr
    try:
        return UnstructuredMesh(points, cells, point_data, cell_data, source=str(path))
    except ValueError as exc:
        raise ReadError(path, str(exc)) from None
