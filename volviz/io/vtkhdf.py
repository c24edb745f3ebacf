"""VTKHDF files (VTK's HDF5 format), including transient ones, through ``vtkHDFReader``.

The file is first checked with h5py: HDF5 signature, a ``/VTKHDF`` group with a ``Type`` attribute, and (for
transient data) ``/VTKHDF/Steps`` with ``Values``. Static files give one dataset; transient files give a TimeSeries
whose frames are read lazily, one vtkHDFReader update per step.
"""
from __future__ import annotations

import numpy as np

from volviz.io._checks import check_finite, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError
from volviz.io.vtkconvert import vtk_to_model
from volviz.model import TimeSeries

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _inspect(path: PathLike) -> tuple[str, np.ndarray | None]:
    """(data set type, step times or None); ReadError if this is not a VTKHDF file."""
    import h5py

    size = file_size(path)
    head = read_bytes(path, 8)
    if head != HDF5_SIGNATURE:
        raise ReadError(path, f"not an HDF5/VTKHDF file: starts with {head!r}")
    try:
        with h5py.File(path, "r") as f:
            if "VTKHDF" not in f or not isinstance(f["VTKHDF"], h5py.Group):
                raise ReadError(path, "HDF5 file without a /VTKHDF group: not a VTKHDF file")
            root = f["VTKHDF"]
            kind = root.attrs.get("Type")
            if kind is None:
                raise ReadError(path, "/VTKHDF has no Type attribute")
            kind = kind.decode() if isinstance(kind, bytes) else str(kind)
            _check_dataset_sizes(path, root, size)
            times = None
            if "Steps" in root:
                steps = root["Steps"]
                if "Values" not in steps:
                    raise ReadError(path, "/VTKHDF/Steps has no Values dataset")
                values = steps["Values"]
                if values.ndim != 1 or values.shape[0] == 0 or values.shape[0] > size:
                    raise ReadError(path, f"/VTKHDF/Steps/Values has shape {values.shape}")
                times = np.asarray(values[()], dtype=np.float64)
                check_finite(path, times, False, "step times")
    except ReadError:
        raise
    except PermissionError:
        raise ReadError(path, "permission denied (the file is not readable)") from None
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ReadError(path, f"HDF5 library could not read the file ({exc})") from None
    return kind, times


def _check_dataset_sizes(path: PathLike, root, size: int) -> None:
    """No dataset may claim more bytes than the file could hold after decompression (deflate stays under
    ~1032:1), so a corrupt shape cannot make VTK allocate a huge array."""
    import h5py

    budget = 1100 * size + (1 << 20)
    found: list[tuple[str, int]] = []

    def visit(name: str, obj) -> None:
        if isinstance(obj, h5py.Dataset):
            found.append((name, int(np.prod(obj.shape, dtype=object)) * obj.dtype.itemsize))

    root.visititems(visit)
    for name, nbytes in found:
        if nbytes > budget:
            raise ReadError(path, f"dataset /VTKHDF/{name} claims {nbytes} bytes, more than the file's {size} bytes "
                                  "can hold even compressed")


def _read_step(path: PathLike, step: int | None, allow_nonfinite: bool):
    import vtk

    from volviz.io.vtkfiles import _run

    reader = vtk.vtkHDFReader()
    reader.SetFileName(str(path))
    if step is not None:
        reader.UpdateInformation()
        reader.SetStep(step)
    return vtk_to_model(path, _run(path, reader), allow_nonfinite)


def read_vtkhdf(path: PathLike, allow_nonfinite: bool = True):
    """Read a VTKHDF file: a model dataset, or a TimeSeries (lazy frames) when the file is transient."""
    _kind, times = _inspect(path)
    if times is None:
        return _read_step(path, None, allow_nonfinite)
    if np.any(np.diff(times) <= 0):
        raise ReadError(path, "step times in /VTKHDF/Steps/Values do not increase strictly")
    first = _read_step(path, 0, allow_nonfinite)
    frames: list = [first] + [None] * (len(times) - 1)
    return TimeSeries(times, frames, loader=lambda i: _read_step(path, i, allow_nonfinite), source=str(path))
