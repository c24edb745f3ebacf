"""VTKHDF files (VTK's HDF5 format), including transient ones, through ``vtkHDFReader``.

The file is first checked with h5py: HDF5 signature, a ``/VTKHDF`` group with a ``Type`` attribute, every count
against the datasets it describes (``volviz.io.vtkhdfcheck``), and (for transient data) ``/VTKHDF/Steps`` with
``Values``; h5py's own exceptions on damaged metadata become ReadError. Static files give one dataset; transient files
give a TimeSeries whose frames are read lazily, one vtkHDFReader update per step.
"""
from __future__ import annotations

import numpy as np

from volviz.io._checks import HDF5_SIGNATURE, check_finite, describe_bytes, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError
from volviz.io.hdf5arrays import has_vtkhdf_group, read_hdf5
from volviz.io.vtk_lazy import vtk
from volviz.io.vtkconvert import vtk_to_model
from volviz.io.vtkfiles import _run
from volviz.io.vtkhdfcheck import check_structure
from volviz.model import TimeSeries


def _inspect(path: PathLike) -> tuple[str, np.ndarray | None]:
    """(data set type, step times or None); ReadError if this is not a VTKHDF file."""
    # heavy: h5py (about 45 modules), loaded only when a VTKHDF file is read
    import h5py

    size = file_size(path)
    head = read_bytes(path, 8)
    if head != HDF5_SIGNATURE:
        raise ReadError(path, f"not an HDF5/VTKHDF file: starts with {describe_bytes(head)}, not the HDF5 signature")
    try:
        with h5py.File(path, "r") as f:
            if "VTKHDF" not in f or not isinstance(f["VTKHDF"], h5py.Group):
                raise ReadError(path, "HDF5 file without a /VTKHDF group: not a VTKHDF file")
            root = f["VTKHDF"]
            kind = check_structure(path, root, size)
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
    except (RuntimeError, OSError, KeyError, ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ReadError(path, f"HDF5 library could not read the file's structure ({type(exc).__name__}: "
                              f"{_printable(exc)})") from None
    return kind, times


def _printable(exc: Exception) -> str:
    """An exception's message, shortened, with anything that is not printable text replaced."""
    return "".join(c if c.isprintable() else "?" for c in str(exc)[:200])


def _read_step(path: PathLike, step: int | None, allow_nonfinite: bool):
    reader = vtk.vtkHDFReader()
    reader.SetFileName(str(path))
    if step is not None:
        reader.UpdateInformation()
        reader.SetStep(step)
    return vtk_to_model(path, _run(path, reader), allow_nonfinite)


def read_vtkhdf(path: PathLike, allow_nonfinite: bool = True):
    """Read a VTKHDF file: a model dataset, or a TimeSeries (lazy frames) when the file is transient. An HDF5 file
    without a /VTKHDF group (a .hdf of arrays) is read by ``volviz.io.hdf5arrays``."""
    if read_bytes(path, 8) == HDF5_SIGNATURE and not has_vtkhdf_group(path):
        return read_hdf5(path, allow_nonfinite=allow_nonfinite)
    _kind, times = _inspect(path)
    if times is None:
        return _read_step(path, None, allow_nonfinite)
    if np.any(np.diff(times) <= 0):
        raise ReadError(path, "step times in /VTKHDF/Steps/Values do not increase strictly")
    first = _read_step(path, 0, allow_nonfinite)
    frames: list = [first] + [None] * (len(times) - 1)
    return TimeSeries(times, frames, loader=lambda i: _read_step(path, i, allow_nonfinite), source=str(path))
