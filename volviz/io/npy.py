"""NumPy ``.npy`` arrays (what ``numpy.save`` writes), read by NumPy without pickles (``allow_pickle=False``).

A 3D array is read (z, y, x), x fastest in memory, as every volviz reader of Python-made arrays reads them (HDF5,
TIFF stacks) and as scikit-image, tifffile and napari index volumes (and as VTK lays out image data): ``a[k, j, i]``
is at ``(i, j, k)``, unit spacing (``order="xyz"`` reads a[i, j, k] there instead: ``volviz.io.axis_order``). A 4D
array whose last axis has 2 to 4 entries is (z, y, x, channels), one array by
magnitude or component; any other 4D array is (t, z, y, x), a time series; a 2D array is an image (rows, columns).
Numbers only: booleans become 0 / 1, complex and record arrays are refused. NumPy maps the data after reading the
header, and refuses a file shorter than the header says; a file longer than its header says is refused too (at least
one slice more) or warned about (``volviz.io.trailing``).
"""
from __future__ import annotations

from tokenize import TokenError
from typing import Any

import numpy as np

from volviz.io._checks import check_file, check_finite
from volviz.io.axis_order import check_order, to_xyz
from volviz.io.errors import PathLike, ReadError
from volviz.io.trailing import check_trailing
from volviz.model import Image2D, RegularVolume, TimeSeries
from volviz.model.arrays import volume_of

MAGIC = b"\x93NUMPY"


def is_npy(head: bytes) -> bool:
    return head.startswith(MAGIC)


def _volume(path: PathLike, data: np.ndarray, name: str, order: str, allow_nonfinite: bool) -> RegularVolume:
    """(z, y, x[, c]) (or in ``order``) -> a volume (x, y, z[, c])."""
    data = to_xyz(data, order)
    check_finite(path, data, allow_nonfinite)
    return volume_of(data, name, source=str(path))


def read_npy(path: PathLike, order: str = "zyx",
             allow_nonfinite: bool = True) -> RegularVolume | TimeSeries | Image2D:
    """A ``.npy`` array as a volume, a volume of vectors, a time series or an image (see the module; ``order``:
    ``volviz.io.axis_order``)."""
    p = check_file(path)
    check_order(p, order)
    try:  # reads the header only; the data is mapped, and a file shorter than its header says is refused here
        data: Any = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError, SyntaxError, TokenError, TypeError, OverflowError, MemoryError) as exc:
        # a damaged header reaches NumPy's literal parser: SyntaxError / TokenError, not only ValueError
        raise ReadError(p, f"not a NumPy .npy file NumPy can read, or shorter than its header says "
                           f"({str(exc)[:200]})") from None
    if not isinstance(data, np.ndarray):
        raise ReadError(p, "is an .npz archive of several arrays, not one .npy array")
    shape, dtype = data.shape, data.dtype
    if isinstance(data, np.memmap) and data.size:  # the header's shape against the bytes after the header
        fortran = data.flags.f_contiguous and not data.flags.c_contiguous
        slowest = shape[-1] if fortran else shape[0]
        check_trailing(p, f"shape {shape} of {dtype}", data.nbytes, p.stat().st_size - data.offset - data.nbytes,
                       data.nbytes // max(slowest, 1))
    if dtype.hasobject or dtype.names is not None or dtype.kind not in "biuf":
        raise ReadError(p, f"holds {dtype} values; volviz reads arrays of numbers (integers, floats, booleans)")
    if len(shape) not in (2, 3, 4) or min(shape, default=0) < 1:
        raise ReadError(p, f"holds an array of shape {shape}; volviz reads 2D images, 3D volumes (z, y, x), and 4D "
                           "arrays (z, y, x, channels) or (time, z, y, x)")
    data = np.asarray(data, dtype=np.uint8 if dtype.kind == "b" else None)
    if not data.dtype.isnative:
        data = data.astype(data.dtype.newbyteorder("="))
    name = p.stem
    if data.ndim == 2:
        check_finite(p, data, allow_nonfinite)
        return Image2D(np.ascontiguousarray(data), source=str(p))
    if data.ndim == 3 or 2 <= data.shape[3] <= 4:
        return _volume(p, data, name, order, allow_nonfinite)
    frames: list[Any] = [_volume(p, data[t], name, order, allow_nonfinite) for t in range(len(data))]
    return TimeSeries(np.arange(len(frames), dtype=np.float64), frames, source=str(p))
