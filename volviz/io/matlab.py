"""MATLAB ``.mat`` files: v5 / v7 through SciPy (``scipy.io.whosmat`` lists the variables without reading them,
``loadmat`` then reads the one shown), v7.3 (HDF5 with a MATLAB header) through h5py.

- Which variable: ``variable="V"``; by default the largest numeric (or logical) 3D / 4D array, the others named in a
  warning; a file of 2D arrays only gives the largest as an image. Structs, cells, strings and complex arrays are
  not volumes (named in the error when nothing else is there).
- Layout: MATLAB's own for volumes, that of ``isosurface`` and ``slice`` (meshgrid order): ``V(r, c, s)`` is at
  x = column c, y = row r, z = slice s. A 4D array whose 4th dimension has 2 to 4 entries is a volume of channels,
  any other one a time series along it. v7.3 files store the transpose, which is undone.
- Unit voxels (a .mat file carries no voxel size). The reader runs isolated: compressed variables can claim any size.
"""
from __future__ import annotations

import mmap
import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import HDF5_SIGNATURE, check_file, check_finite, read_bytes
from volviz.io.array_choice import choose_array
from volviz.io.errors import PathLike, ReadError
from volviz.io.matcheck import check_mat5
from volviz.model import Image2D, RegularVolume, TimeSeries
from volviz.model.arrays import volume_of

_NUMERIC = ("double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "logical")


def is_mat(head: bytes) -> bool:
    """A level 5 MAT-file (v5, v7, v7.3) announces itself in its 116-byte text header."""
    return head.startswith((b"MATLAB 5.0 MAT-file", b"MATLAB 7.3 MAT-file"))


def _choose(path: PathLike, found: list[tuple[str, tuple[int, ...]]], variable: str | None, others: list[str]) -> str:
    """The variable to show among ``found`` (name, MATLAB shape) numeric arrays of 2 to 4 dimensions."""
    return choose_array(path, found, variable, "variable",
                        "holds no numeric 2D to 4D array" + (f" (only {', '.join(others)})" if others else ""))


def _v5(path: PathLike, variable: str | None) -> tuple[str, np.ndarray]:
    # heavy: SciPy's io (about 250 modules), loaded only when a MATLAB file is read
    import scipy.io

    with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
        check_mat5(Path(path), data)  # SciPy trusts the tags: IndexError, zlib's words, even a crash
    try:
        listed = scipy.io.whosmat(str(path))
        found, others = [], []
        for name, shape, kind in listed:
            shape = tuple(int(n) for n in shape)
            if kind in _NUMERIC and 2 <= len(shape) <= 4 and min(shape) > 1:
                found.append((name, shape))
            else:
                others.append(f"{name} ({kind})")
        name = _choose(path, found, variable, others)
        values = scipy.io.loadmat(str(path), variable_names=[name], squeeze_me=False, mat_dtype=False)[name]
    except ReadError:
        raise
    except zlib.error as exc:
        raise ReadError(path, f"a compressed variable's zlib data is damaged ({exc})") from None
    except (ValueError, TypeError, OSError, EOFError, KeyError, NotImplementedError, MemoryError, IndexError,
            struct.error, UnicodeDecodeError, OverflowError) as exc:
        raise ReadError(path, f"SciPy could not read the MAT-file ({type(exc).__name__}: {str(exc)[:200]})") from None
    return name, np.asarray(values)


def _v73(path: PathLike, variable: str | None) -> tuple[str, np.ndarray]:
    # heavy: h5py (about 45 modules), loaded only for a v7.3 (HDF5) MATLAB file
    import h5py

    try:
        with h5py.File(str(path), "r") as f:
            found, others = [], []
            for name, obj in f.items():
                kind = obj.attrs.get("MATLAB_class", b"")
                kind = kind.decode() if isinstance(kind, bytes) else str(kind)
                shape = tuple(int(n) for n in reversed(obj.shape)) if isinstance(obj, h5py.Dataset) else ()
                if isinstance(obj, h5py.Dataset) and kind in _NUMERIC and 2 <= len(shape) <= 4 and min(shape) > 1 \
                        and obj.dtype.kind in "biuf":
                    found.append((name, shape))
                elif not name.startswith("#"):
                    others.append(f"{name} ({kind or 'group'})")
            name = _choose(path, found, variable, others)
            values = f[name][()]
    except ReadError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError, MemoryError) as exc:
        raise ReadError(path, f"the HDF5 library could not read the v7.3 MAT-file ({type(exc).__name__}: "
                              f"{str(exc)[:200]})") from None
    return name, np.transpose(values)  # v7.3 stores MATLAB's column-major array as its C-order transpose


def _volume(path: PathLike, values: np.ndarray, name: str, allow_nonfinite: bool) -> RegularVolume:
    """``V(r, c, s[, k])`` -> a volume (x = c, y = r, z = s[, k])."""
    data = np.ascontiguousarray(np.swapaxes(values, 0, 1))
    check_finite(path, data, allow_nonfinite)
    return volume_of(data, name, source=str(path))


def read_mat(path: PathLike, variable: str | None = None,
             allow_nonfinite: bool = True) -> RegularVolume | TimeSeries | Image2D:
    """A MAT-file's array as a volume, a time series or an image (see the module)."""
    p = check_file(path)
    head = read_bytes(p, 520)
    if not is_mat(head):
        raise ReadError(p, "not a level 5 MAT-file (v5, v7 or v7.3); save it with MATLAB's save -v7 or -v7.3")
    name, values = _v73(p, variable) if head[512:520] == HDF5_SIGNATURE else _v5(p, variable)
    if values.dtype.kind == "b":
        values = values.astype(np.uint8)
    if values.dtype.kind not in "iuf":
        raise ReadError(p, f"its variable {name} holds {values.dtype} values, not real numbers")
    if values.ndim == 2:
        check_finite(p, values, allow_nonfinite)
        return Image2D(np.ascontiguousarray(values), source=str(p))
    if values.ndim == 3 or 2 <= values.shape[3] <= 4:
        return _volume(p, values, name, allow_nonfinite)
    frames: list[Any] = [_volume(p, values[..., t], name, allow_nonfinite) for t in range(values.shape[3])]
    return TimeSeries(np.arange(len(frames), dtype=np.float64), frames, source=str(p))
