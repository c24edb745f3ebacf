"""MINC 1 (netCDF) and MINC 2 (HDF5) volumes (``.mnc``, the MNI's format: BrainWeb, the MNI templates, CIVET and
minc-toolkit output) through nibabel.

- Values through the file's per-slice image-min / image-max scaling, as nibabel's array proxy applies it.
- Placement: nibabel's voxel-to-world affine over the three ``*space`` dimensions, in the file's order, through
  ``placement.aligned_volume`` (MINC's world is RAS, as NIfTI's).
- A ``time`` dimension (MINC puts it first) becomes a ``TimeSeries`` at its step (seconds in MINC), a step read when it
  is shown; ``time_index=i`` reads one. A ``vector_dimension`` (RGB, displacement) gives components.
- Before any voxel is read, the data size is held against the file: a MINC 2 dataset may be compressed, so it must
  be one the file could inflate to.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import file_size
from volviz.io.errors import PathLike, ReadError, human_bytes
from volviz.io.metaimage import DEFLATE_MAX_RATIO
from volviz.model import RegularVolume, TimeSeries

from volviz_imaging.nifti import load_image, time_step, volume_or_series, voxels
from volviz_imaging.placement import aligned_volume


def dimension_names(img: Any) -> list[str]:
    """The names of the image's dimensions (``time``, ``zspace`` ... ``vector_dimension``), slowest first."""
    names = getattr(getattr(img.dataobj, "minc_file", None), "_dim_names", None)
    if names is None or len(names) != len(img.shape):        # nibabel keeps them privately; else MINC's usual order
        return ["time", "zspace", "yspace", "xspace"][-len(img.shape):]
    return [n.decode() if isinstance(n, bytes) else str(n) for n in names]


def read_minc(path: PathLike, time_index: int | None = None,
              allow_nonfinite: bool = True) -> RegularVolume | TimeSeries:
    """A MINC volume, or its time dimension as a time series (see the module)."""
    img = load_image(path, "MINC")
    shape = tuple(int(n) for n in img.shape)
    names = dimension_names(img)
    spatial = [i for i, n in enumerate(names) if n.endswith("space")]
    time = [i for i, n in enumerate(names) if n == "time"]
    vector = [i for i, n in enumerate(names) if n == "vector_dimension"]
    if len(spatial) != 3 or len(spatial) + len(time) + len(vector) != len(shape) or min(shape) < 1:
        raise ReadError(path, f"its dimensions are {', '.join(f'{n} {s}' for n, s in zip(names, shape))}: volviz "
                              "reads three space dimensions, with a time and a vector dimension at most")
    needed = int(np.prod(shape, dtype=object)) * img.get_data_dtype().itemsize
    if needed > DEFLATE_MAX_RATIO * file_size(path) + 4096:
        raise ReadError(path, f"its header claims {'x'.join(map(str, shape))} voxels ({human_bytes(needed)}), more "
                              "than the file could hold even compressed: the header is wrong")
    n_steps = shape[time[0]] if time else 1
    order = spatial + vector                       # axes left after the time index is taken, in that order
    kept = [i for i in range(len(shape)) if not (time and i == time[0])]
    name = Path(path).name.removesuffix(".mnc") or Path(path).name

    def volume(t: int | None) -> RegularVolume:
        index: list[Any] = [slice(None)] * len(shape)
        if time:
            index[time[0]] = t or 0
        data = voxels(path, img, tuple(index))
        data = np.transpose(data, [kept.index(i) for i in order])
        return aligned_volume(path, data, img.affine, name, allow_nonfinite=allow_nonfinite, warn=not t)

    return volume_or_series(path, volume, n_steps, time_step(img, time[0]) if time else 1.0, time_index)
