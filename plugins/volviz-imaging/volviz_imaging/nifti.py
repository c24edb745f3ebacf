"""NIfTI-1 and NIfTI-2 (.nii, .nii.gz, .hdr/.img pairs), Analyze 7.5 (.hdr/.img) and FreeSurfer MGH (.mgh, .mgz)
through nibabel.

- Values are the file's stored values through its scaling (``scl_slope`` / ``scl_inter``: a CT stored as int16 with
  slope 1, intercept -1024 shows Hounsfield units), as nibabel's array proxy applies it.
- Placement: the file's voxel-to-RAS affine (sform, else qform, else the voxel sizes), through
  ``placement.aligned_volume``.
- A 4D file (fMRI, a sequence) becomes a ``TimeSeries``: one volume per step at ``t x pixdim[4]`` (in the file's
  time unit; step numbers when it has none), each read when it is shown; ``time_index=i`` reads one step. A 5D file
  of one time step (NIfTI's vector intents: displacement fields, RGB) gives one array with its components.
- Before any voxel is read, the header's data size is checked against the file (an uncompressed file that is too
  short, a compressed one that could not inflate to it; an uncompressed NIfTI / Analyze file that holds a slice or
  more beyond its header's dims is refused, fewer extra bytes are a ``ReadWarning``: ``volviz.io.trailing``).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import numpy as np

from volviz.io._checks import check_file, file_size, require_bytes
from volviz.io.errors import PathLike, ReadError, human_bytes
from volviz.io.trailing import check_trailing
from volviz.io.metaimage import DEFLATE_MAX_RATIO
from volviz.model import RegularVolume, TimeSeries

from volviz_imaging.placement import aligned_volume

_TIME_UNITS = {"msec": 1e-3, "usec": 1e-6, "sec": 1.0}


def load_image(path: PathLike, what: str = "NIfTI, Analyze or MGH") -> Any:
    """nibabel's image of the file (its header read, no voxel yet); ReadError naming the file otherwise."""
    import nibabel as nib
    from nibabel.filebasedimages import ImageFileError

    p = check_file(path)
    try:
        return nib.load(p)
    except FileNotFoundError as exc:
        raise ReadError(p, f"its data file {Path(exc.filename or '').name or '(unknown)'} is not beside it (an "
                           "Analyze / NIfTI pair needs both the .hdr and the .img)") from None
    except (ImageFileError, nib.spatialimages.HeaderDataError, ValueError, OSError, EOFError) as exc:
        raise ReadError(p, f"not a {what} image nibabel can read ({exc})") from None


def _name(path: PathLike) -> str:
    name = Path(path).name
    for ext in (".nii.gz", ".nii", ".hdr", ".img", ".mgh", ".mgz"):
        if name.lower().endswith(ext):
            return name[: -len(ext)] or name
    return name


def _check_size(path: PathLike, img: Any) -> None:
    """The header's voxels fit in the data file (uncompressed), or could inflate from it (gzip)."""
    dtype = img.get_data_dtype()
    needed = int(np.prod(img.shape, dtype=object)) * dtype.itemsize
    image_file = img.file_map["image"].filename or str(path)
    data = Path(image_file)
    if not data.is_file():
        raise ReadError(path, f"its data file {data.name} is not beside it (an Analyze / NIfTI pair needs both the "
                              ".hdr and the .img)")
    size = file_size(data)
    offset = int(getattr(img.dataobj, "offset", 0))  # where the proxy starts reading (NIfTI's vox_offset)
    what = f"{'x'.join(str(n) for n in img.shape)} {dtype.name} voxels"
    if data.name.lower().endswith((".gz", ".mgz")):
        if needed + offset > DEFLATE_MAX_RATIO * size + 64:
            raise ReadError(path, f"its header claims {what} ({human_bytes(needed)}), more than its {size} "
                                  f"compressed bytes can inflate to: the header is wrong")
    else:
        require_bytes(data, needed, size - offset, what)
        if type(img).__name__ != "MGHImage":  # MGH keeps scan parameters and tags after its voxels
            dims = ", ".join(f"dim[{i + 1}] {n}" for i, n in enumerate(img.shape))
            check_trailing(path, f"{dims} of {dtype.name}", needed, size - offset - needed,
                           needed // max(int(img.shape[-1]), 1))


def time_step(img: Any, axis: int = 3) -> float:
    """The time between volumes (``axis`` of the image) in seconds when the file says so, else 1 (steps)."""
    header = img.header
    try:
        step = float(header.get_zooms()[axis])
        unit = header.get_xyzt_units()[1] if hasattr(header, "get_xyzt_units") else "unknown"
    except (IndexError, TypeError, ValueError):
        return 1.0
    if not np.isfinite(step) or step <= 0:
        return 1.0
    return step * _TIME_UNITS.get(unit, 1.0)


def voxels(path: PathLike, img: Any, index: tuple) -> np.ndarray:
    """The scaled voxels at ``index`` (nibabel's proxy applies scl_slope / scl_inter), RGB records as components."""
    try:
        data = np.asanyarray(img.dataobj[index])
    except (ValueError, OSError, EOFError, MemoryError) as exc:
        raise ReadError(path, f"its voxel data could not be read ({exc})") from None
    if data.dtype.names:  # NIfTI RGB24 / RGBA32 records
        data = np.stack([data[n] for n in data.dtype.names], axis=-1)
    return data


def read_nifti(path: PathLike, time_index: int | None = None,
               allow_nonfinite: bool = True) -> RegularVolume | TimeSeries:
    """A NIfTI / Analyze / MGH file as a volume, or its 4th dimension as a time series (see the module)."""
    img = load_image(path)
    shape = tuple(int(n) for n in img.shape)
    if len(shape) < 3:
        shape = shape + (1,) * (3 - len(shape))
    if len(shape) > 5 or (len(shape) == 5 and shape[3] != 1) or any(n < 1 for n in shape):
        raise ReadError(path, f"a {len(img.shape)}D image of shape {'x'.join(map(str, img.shape))}: volviz reads "
                              "3D volumes, 4D time series and 5D vector volumes of one time step")
    _check_size(path, img)
    affine = img.affine
    if affine is None:
        affine = np.diag(list(img.header.get_zooms()[:3]) + [1.0])
    name = _name(path)

    def volume(t: int | None) -> RegularVolume:
        if len(img.shape) < 3:
            data = voxels(path, img, (Ellipsis,)).reshape(shape[:3])
        elif len(shape) == 5:
            data = voxels(path, img, (Ellipsis, 0, slice(None)))
        elif len(shape) == 4:
            data = voxels(path, img, (Ellipsis, t or 0))
        else:
            data = voxels(path, img, (Ellipsis,))
        return aligned_volume(path, data, affine, name, allow_nonfinite=allow_nonfinite, warn=not t)

    return volume_or_series(path, volume, shape[3] if len(shape) == 4 else 1, time_step(img), time_index)


def volume_or_series(path: PathLike, volume: Callable[[int | None], RegularVolume], n_steps: int, step: float,
                     time_index: int | None) -> RegularVolume | TimeSeries:
    """Step ``time_index`` of an image of ``n_steps`` volumes, ``step`` seconds apart; without it the one volume,
    or a TimeSeries whose later steps are read when shown (``volume(t)`` reads step t)."""
    if time_index is not None:
        if not 0 <= time_index < n_steps:
            raise ReadError(path, f"time_index {time_index} is out of range: the file has {n_steps} time step(s)")
        return volume(time_index)
    if n_steps == 1:
        return volume(0)
    frames: list[Any] = [volume(0)] + [None] * (n_steps - 1)
    return TimeSeries(np.arange(n_steps) * step, frames, loader=volume, source=str(path))
