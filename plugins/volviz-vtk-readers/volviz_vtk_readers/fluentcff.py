"""Fluent case and data in the Common Fluid Format (``NAME.cas.h5`` + ``NAME.dat.h5``, HDF5) through VTK's
``vtkFLUENTCFFReader``: the case's cell zones merged, with every cell field (the ``SV_*`` arrays) of the data file.

VTK's reader finds the data file by replacing the case's ``.cas.h5`` with ``.dat.h5``, so the pair must be named so:
a case under another name, a data file without its case, or a case without its data are said before VTK runs (the
last is read, mesh only, with a ReadWarning). Both files are checked against their HDF5 superblock first (a
truncated file is refused), the data file must open as Fluent CFF data and each cell field (``SV_*``) must hold one
value row per cell of its zone in the case (VTK's reader read a data file cut in its superblock as the case alone),
and the reader runs isolated like every loader of this plugin.
"""
from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, Sequence

from volviz.io.errors import PathLike, ReadError, ReadWarning

from volviz_vtk_readers.containers import check_container

CASE, DATA = ".cas.h5", ".dat.h5"


def _cff_part(path: Path) -> str | None:
    """``"case"`` (``/meshes``), ``"data"`` (``/results``) or None when the HDF5 file is not Fluent CFF."""
    import h5py

    from volviz.io.hdf5kind import kind_of_open

    try:
        with h5py.File(path, "r") as f:
            if kind_of_open(f) != "fluent-cff":
                return None
            return "case" if isinstance(f.get("meshes"), h5py.Group) else "data"
    except (OSError, RuntimeError, ValueError, KeyError, TypeError) as exc:
        raise ReadError(path, f"the HDF5 library could not read it ({type(exc).__name__}: {str(exc)[:200]})") from None


def case_file(path: PathLike) -> Path:
    """The checked case file to give VTK for ``path`` (a case, or a data file with its case beside it)."""
    p = check_container(path, "Fluent CFF", netcdf=False)
    part = _cff_part(p)
    if part is None:
        raise ReadError(p, "is HDF5 but not a Fluent CFF case or data file (no /meshes or /results beside /settings)")
    name = p.name.lower()
    if part == "data":
        if not name.endswith(DATA):
            raise ReadError(p, "is Fluent CFF data (the fields, without the mesh)",
                            f"name it NAME{DATA} beside its case NAME{CASE} and open the case")
        case = p.with_name(p.name[:-len(DATA)] + CASE)
        if not case.is_file():
            raise ReadError(p, f"is Fluent CFF data (the fields, without the mesh); its case file {case.name} is not "
                               "beside it", f"put {case.name} beside it and open that")
        p = check_container(case, "Fluent CFF", netcdf=False)
        if _cff_part(p) != "case":
            raise ReadError(p, "is not a Fluent CFF case file (no /meshes group)")
    elif not name.endswith(CASE):
        raise ReadError(p, "is a Fluent CFF case, but VTK's reader finds its data only when it is named "
                           f"NAME{CASE}", f"rename it NAME{CASE} (its data file NAME{DATA}) and open it again")
    data = p.with_name(p.name[:-len(CASE)] + DATA)
    if not data.is_file():
        warnings.warn(ReadWarning(f"{p}: no data file {data.name} beside it: the mesh is shown without fields"),
                      stacklevel=3)
    else:
        check_container(data, "Fluent CFF", netcdf=False)
        if _cff_part(data) != "data":
            raise ReadError(data, f"is the data file of {p.name} but not Fluent CFF data (no /results beside "
                                  "/settings)")
        check_cell_fields(p, data)
    return p


def _cell_count(case: Path) -> int | None:
    """The cells of the case's first mesh: the sum over its cell zones of ``maxId - minId + 1``
    (``meshes/1/cells/zoneTopology``); None when the case does not say."""
    import h5py
    import numpy as np

    with h5py.File(case, "r") as f:
        topology = f.get("meshes/1/cells/zoneTopology")
        if not isinstance(topology, h5py.Group) or not {"minId", "maxId"} <= set(topology):
            return None
        lo, hi = (np.asarray(topology[k][()], dtype=np.int64).reshape(-1) for k in ("minId", "maxId"))
    return int((hi - lo + 1).sum()) if lo.shape == hi.shape else None


def check_cell_fields(case: Path, data: Path) -> None:
    """Every cell field of the data file (``results/1/<phase>/cells/SV_*``, one dataset per zone section) holds one
    row per cell of the case in all: VTK's reader takes a field of another length without a word."""
    import h5py

    cells = _cell_count(case)
    if cells is None:
        return
    try:
        with h5py.File(data, "r") as f:
            results = f.get("results/1")
            for phase in results.values() if isinstance(results, h5py.Group) else []:
                fields = phase.get("cells") if isinstance(phase, h5py.Group) else None
                for name, field in fields.items() if isinstance(fields, h5py.Group) else []:
                    if not isinstance(field, h5py.Group):
                        continue
                    rows = sum(v.shape[0] for v in field.values() if isinstance(v, h5py.Dataset) and v.shape)
                    if rows != cells:
                        raise ReadError(data, f"cell field {field.name} holds {rows} values but the case "
                                              f"{case.name} has {cells} cells")
    except (OSError, RuntimeError, ValueError, KeyError, TypeError) as exc:
        raise ReadError(data, f"the HDF5 library could not read its cell fields ({type(exc).__name__}: "
                              f"{str(exc)[:200]})") from None


def fluent_cff_reader(path: PathLike) -> Any:
    """A ``vtkFLUENTCFFReader`` on the case of ``path`` with every cell array on (information read)."""
    from volviz_vtk_readers.readers import _information, _reader

    reader = _information(path, _reader("vtkFLUENTCFFReader", case_file(path)))
    reader.EnableAllCellArrays()
    return reader


def read_fluent_cff(path: PathLike, blocks: Sequence[str] | str | None = None, allow_nonfinite: bool = True):
    """Fluent CFF (``.cas.h5``, or its ``.dat.h5``): every cell zone (or ``blocks``) with every cell field, merged."""
    from volviz.io.vtkfiles import _run

    from volviz_vtk_readers.readers import _convert

    return _convert(path, blocks, allow_nonfinite)(_run(path, fluent_cff_reader(path)))
