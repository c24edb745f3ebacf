"""Headerless binary volumes: one file (``read_raw``) or a stack of slice files (``read_slice_stack``).

The caller gives what the file cannot: dimensions (x fastest), sample type and byte order. The file size must
match exactly (``header_bytes`` + voxels x sample size); a mismatch means wrong dimensions or type and is reported.
"""
from __future__ import annotations

from typing import Literal, Sequence

import numpy as np
from numpy.typing import DTypeLike

from volviz.io._checks import check_dims, check_finite, describe_dims, file_size, read_at
from volviz.io.errors import PathLike, ReadError, bytes_and_size, human_bytes
from volviz.io.series import expand_pattern
from volviz.model import Image2D, RegularVolume, vec3

_BYTEORDERS: dict[str, Literal["<", ">", "="]] = {"little": "<", "<": "<", "big": ">", ">": ">", "native": "=",
                                                  "=": "=", "msb": ">", "lsb": "<"}


def file_dtype(dtype: DTypeLike, byteorder: str) -> np.dtype:
    """The on-disk dtype for a sample type and byte order ("little", "big", "native", "<", ">", "=")."""
    try:
        bo = _BYTEORDERS[str(byteorder).lower()]
    except KeyError:
        raise ValueError(f"byteorder must be one of {sorted(_BYTEORDERS)}, got {byteorder!r}") from None
    dt = np.dtype(dtype)
    if dt.kind not in "uif" or dt.itemsize > 8:
        raise ValueError(f"raw volumes hold integer or float samples, not {dt}")
    return dt.newbyteorder(bo) if dt.itemsize > 1 else dt


def decode_samples(path: PathLike, raw: bytes | bytearray, disk: np.dtype, allow_nonfinite: bool) -> np.ndarray:
    """Bytes -> native-endian samples, with the finite check for float data."""
    values = np.frombuffer(raw, dtype=disk)
    if not disk.isnative:
        values = values.astype(disk.newbyteorder("="))
    check_finite(path, values, allow_nonfinite)
    return values


def swapped_looks_right(raw: bytes | bytearray, disk: np.dtype, samples: int = 65536) -> str | None:
    """Why multi-byte samples read in ``disk``'s byte order look byte-swapped, or None when the stored reading is as
    plausible (noise, constant data, single bytes). Over the first ``samples`` samples in file order: integers whose
    least significant byte is 0 in every sample while the other bytes vary (small values stored in the other order),
    or whose median step between neighbours, over their 5-95 % spread, is at least 8 times the swapped reading's (a
    finely sampled field varies smoothly, its swapped bytes do not); floats of which a tenth or more are not finite,
    beyond 1e30 or within 1e-30 of 0 while at most 1 % are so swapped (random exponent bits). The mark of a byte
    order a header failed to state."""
    if disk.itemsize == 1:
        return None
    n = min(len(raw) // disk.itemsize, samples)
    if n < 16:
        return None
    head = np.frombuffer(raw, dtype=np.uint8, count=n * disk.itemsize).reshape(n, disk.itemsize)
    low = head[:, -1] if disk.byteorder == ">" else head[:, 0]     # the least significant byte as read
    if disk.kind in "iu" and not low.any() and head.any():
        return "every sample's low byte is 0, as when small values are stored in the other byte order"
    stored, swapped = np.frombuffer(raw, dtype=disk, count=n), np.frombuffer(raw, dtype=disk.newbyteorder(), count=n)
    if disk.kind == "f":
        a, b = _implausible_share(stored), _implausible_share(swapped)
        if a >= 0.1 and b <= 0.01:
            return (f"{a:.0%} of the samples are not finite, beyond 1e30 or within 1e-30 of 0 (not 0), read in the "
                    f"other byte order {b:.0%}")
        return None
    a, b = _relative_step(stored.astype(np.float64)), _relative_step(swapped.astype(np.float64))
    if b < np.inf and a > 8.0 * b:
        return f"read in the other byte order they vary far more smoothly (median step {b:.3g} against {a:.3g})"
    return None


def _implausible_share(values: np.ndarray) -> float:
    """The share of float samples no field holds: not finite, beyond 1e30, or within 1e-30 of 0 but not 0 (what
    random exponent bits give)."""
    with np.errstate(invalid="ignore", over="ignore"):
        mag = np.abs(values.astype(np.float64))
    odd = ~np.isfinite(mag) | (mag > 1e30) | ((mag < 1e-30) & (mag > 0))
    return float(odd.mean())


def _relative_step(values: np.ndarray) -> float:
    """The median step between neighbouring samples over their 5-95 % spread (inf when they do not spread)."""
    lo, hi = np.percentile(values, [5.0, 95.0])
    return float(np.median(np.abs(np.diff(values))) / (hi - lo)) if hi > lo else np.inf


def _size_problem(path: PathLike, dims: Sequence[int], disk: np.dtype, header_bytes: int, size: int) -> None:
    need = header_bytes + int(np.prod([int(d) for d in dims], dtype=object)) * disk.itemsize
    if need != size:
        claim = f"{describe_dims(dims)} samples of {disk.itemsize} byte(s)"
        if header_bytes:
            claim += f" after a {header_bytes}-byte header"
        more = "more" if size > need else "less"
        raise ReadError(path, f"{claim} need {bytes_and_size(need)} but the file holds {size} bytes "
                              f"({human_bytes(size)}, {abs(size - need)} {more}): wrong dimensions, type or header")


def read_raw(path: PathLike, dims: Sequence[int], dtype: DTypeLike, byteorder: str = "little", header_bytes: int = 0,
             spacing: Sequence[float] = (1.0, 1.0, 1.0), origin: Sequence[float] = (0.0, 0.0, 0.0),
             allow_nonfinite: bool = True, name: str = "scalars") -> RegularVolume | Image2D:
    """Read a headerless volume (dims (nx, ny, nz), x fastest) or image (dims (nx, ny) -> Image2D (ny, nx))."""
    dims = check_dims(path, dims, "raw dimensions")
    if len(dims) not in (2, 3):
        raise ValueError(f"dims must be (nx, ny) or (nx, ny, nz), got {dims}")
    if header_bytes < 0:
        raise ValueError(f"header_bytes must be >= 0, got {header_bytes}")
    disk = file_dtype(dtype, byteorder)
    size = file_size(path)
    _size_problem(path, dims, disk, header_bytes, size)
    n = int(np.prod(dims))
    values = decode_samples(path, read_at(path, header_bytes, n * disk.itemsize), disk, allow_nonfinite)
    if len(dims) == 2:
        return Image2D(values.reshape(dims[1], dims[0]), spacing=(spacing[0], spacing[1]),
                       origin=(origin[0], origin[1]), source=str(path))
    return RegularVolume(values.reshape(dims, order="F"), spacing=vec3(spacing, "spacing"),
                         origin=vec3(origin, "origin"), name=name, source=str(path))


def read_slice_stack(pattern: str | Sequence[PathLike], dims: Sequence[int], dtype: DTypeLike,
                     byteorder: str = "little", header_bytes: int = 0,
                     spacing: Sequence[float] = (1.0, 1.0, 1.0), origin: Sequence[float] = (0.0, 0.0, 0.0),
                     allow_nonfinite: bool = True, name: str = "scalars") -> RegularVolume:
    """Stack numbered slice files (e.g. ``headsq/quarter.%d`` or ``headsq/quarter.*``) into one RegularVolume.

    ``dims`` is (nx, ny) of one slice, or (nx, ny, nz) to also check the number of slices. Slices are ordered by
    their number (``quarter.2`` before ``quarter.10``) and stacked along z. Every file's size is checked before
    anything is allocated.
    """
    paths = [p for _, p in expand_pattern(pattern)]
    nx, ny, *rest = check_dims(str(pattern), dims, "slice dimensions")
    if rest and rest[0] != len(paths):
        raise ReadError(str(pattern), f"dims ask for {rest[0]} slices but {len(paths)} files match")
    disk = file_dtype(dtype, byteorder)
    for p in paths:
        _size_problem(p, (nx, ny), disk, header_bytes, file_size(p))
    nz = len(paths)
    volume = np.empty((nx, ny, nz), dtype=disk.newbyteorder("="), order="F")
    for k, p in enumerate(paths):
        values = decode_samples(p, read_at(p, header_bytes, nx * ny * disk.itemsize), disk, allow_nonfinite)
        volume[:, :, k] = values.reshape((nx, ny), order="F")
    return RegularVolume(volume, spacing=vec3(spacing, "spacing"), origin=vec3(origin, "origin"), name=name,
                         source=str(paths[0]))
