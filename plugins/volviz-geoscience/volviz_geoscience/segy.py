"""SEG-Y (``.sgy``, ``.segy``; revisions 0-2, IBM or IEEE floats, integers, either byte order) through segyio.

- A post-stack 3D survey (traces with inline and crossline numbers at bytes 189 / 193, the SEG-Y rev. 1 places, on
  a regular grid) is a ``RegularVolume`` of amplitudes: x along the inlines' order, y along the crosslines', z up.
- Spacing: the bin sizes from the traces' CDP coordinates (bytes 181 / 185, scaled by byte 71), in the survey's own
  frame (its rotation against the map dropped, its handedness kept: a survey whose crossline axis lies clockwise of
  its inline axis on the map is shown with the crosslines reversed, so north stays left of east). Without
  coordinates one unit per line.
- The time axis downwards: z = -t with t in milliseconds shown as metres (1 ms for 1 m is a two-way velocity of
  2 km/s, the proportions a seismic viewer's default vertical scale gives); a depth survey's samples in its own unit.
- A file without a 3D geometry (a 2D line, unsorted traces) is an ``Image2D`` section: one column per trace, time
  down the rows.
- Pre-stack files (several offsets per bin) are refused; segyio's own checks of the headers against the file's size
  come first, and every loader runs isolated.
"""
from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, check_finite, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.model import Image2D, RegularVolume

from volviz_geoscience.specs import is_segy


def _coordinates(f: Any, traces: list[int]) -> np.ndarray:
    """The CDP (x, y) of ``traces`` in the file's coordinate unit, through the coordinate scalar (byte 71)."""
    import segyio

    field = segyio.TraceField
    out = []
    for t in traces:
        header = f.header[t]
        scalar = float(header[field.SourceGroupScalar])
        factor = 1.0 if scalar == 0 else (scalar if scalar > 0 else 1.0 / -scalar)
        out.append((header[field.CDP_X] * factor, header[field.CDP_Y] * factor))
    return np.asarray(out, dtype=np.float64)


def _bins(f: Any, n_il: int, n_xl: int) -> tuple[float, float, bool]:
    """The inline and crossline bin sizes and whether the crossline axis lies clockwise of the inline axis; one unit
    each (and no flip) when the traces carry no usable coordinates."""
    if n_il < 2 or n_xl < 2:
        return 1.0, 1.0, False
    first, along_il, along_xl = _coordinates(f, [0, n_xl, 1]) if f.sorting == 2 else \
        _coordinates(f, [0, 1, n_il])                         # inline sorted: traces of one inline are consecutive
    a, b = along_il - first, along_xl - first
    di, dj = float(np.hypot(*a)), float(np.hypot(*b))
    if not (np.isfinite(di) and np.isfinite(dj)) or di <= 0 or dj <= 0:
        return 1.0, 1.0, False
    return di, dj, bool(a[0] * b[1] - a[1] * b[0] < 0)


def _open(path: Path, geometry: bool) -> Any:
    import segyio

    try:
        return segyio.open(str(path), "r", ignore_geometry=not geometry, strict=True)
    except (RuntimeError, ValueError, OSError, IndexError, KeyError) as exc:
        raise ReadError(path, f"segyio cannot read it ({exc})") from None


def read_segy(path: PathLike, allow_nonfinite: bool = True) -> RegularVolume | Image2D:
    """A SEG-Y file as a volume of amplitudes (a 3D survey) or an image (a 2D section); see the module."""
    import segyio

    p = check_file(path)
    head = read_bytes(p, 4096)
    if not is_segy(head):
        raise ReadError(p, f"is not a SEG-Y file (no textual and binary header with a known sample format; its "
                           f"content is {describe_bytes(head)})")
    try:
        f = _open(p, geometry=True)
        why = "its traces are not sorted by inline and crossline" if f.unstructured else ""
    except ReadError as exc:
        f, why = None, exc.problem
    if f is None or why:
        if f is not None:
            f.close()
        return _section(p, allow_nonfinite, why)
    with f:
        if len(f.offsets) > 1:
            raise ReadError(p, f"is a pre-stack file ({len(f.offsets)} offsets per bin); volviz reads post-stack "
                               "volumes")
        try:
            cube = segyio.tools.cube(f)                       # (inline, crossline, sample) in the file's line order
            samples = np.asarray(f.samples, dtype=np.float64)
            n_il, n_xl = len(f.ilines), len(f.xlines)
            di, dj, mirrored = _bins(f, n_il, n_xl)
        except (RuntimeError, ValueError, OSError, IndexError) as exc:
            raise ReadError(p, f"its traces could not be read ({exc})") from None
    if f.sorting == 1:                                        # crossline sorted: (crossline, inline, sample)
        cube = np.swapaxes(cube, 0, 1)
    dt = _sample_interval(p, samples)
    data = np.ascontiguousarray(cube[:, ::-1 if mirrored else 1, ::-1], dtype=np.float32)   # z up: deepest first
    check_finite(p, data, allow_nonfinite, "amplitudes")
    return RegularVolume(data, spacing=(di, dj, dt), origin=(0.0, 0.0, -float(samples[-1])), name="amplitude",
                         source=str(p))


def _sample_interval(p: Path, samples: np.ndarray) -> float:
    if len(samples) < 2:
        return 1.0
    dt = float(samples[1] - samples[0])
    if not np.isfinite(dt) or dt <= 0:
        warnings.warn(f"{p}: its sample interval ({dt}) is not positive; one unit per sample is shown", ReadWarning,
                      stacklevel=3)
        return 1.0
    return dt


def _section(p: Path, allow_nonfinite: bool, why: str) -> Image2D:
    """The traces of a file without a 3D geometry side by side: rows are samples (time down), columns traces; a
    ReadWarning says why it is not a volume."""
    with _open(p, geometry=False) as f:
        try:
            traces = f.trace.raw[:]
            samples = np.asarray(f.samples, dtype=np.float64)
        except (RuntimeError, ValueError, OSError, IndexError) as exc:
            raise ReadError(p, f"its traces could not be read ({exc})") from None
    if traces.ndim != 2 or traces.shape[0] == 0:
        raise ReadError(p, "holds no traces")
    data = np.ascontiguousarray(traces.T, dtype=np.float32)
    check_finite(p, data, allow_nonfinite, "amplitudes")
    warnings.warn(f"{p}: shown as a 2D section of {data.shape[1]} traces: {why}", ReadWarning, stacklevel=3)
    return Image2D(data, spacing=(1.0, _sample_interval(p, samples)), origin=(0.0, -float(samples[-1])),
                   source=str(p))
