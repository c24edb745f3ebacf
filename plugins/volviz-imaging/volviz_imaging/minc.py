"""MINC 1 (netCDF) and MINC 2 (HDF5) volumes (``.mnc``, the MNI's format: BrainWeb, the MNI templates, CIVET and
minc-toolkit output) through nibabel.

- Values through the file's per-slice image-min / image-max scaling, as nibabel's array proxy applies it.
- Placement: nibabel's voxel-to-world affine over the three ``*space`` dimensions, in the file's order, through
  ``placement.aligned_volume`` (MINC's world is RAS, as NIfTI's).
- A ``time`` dimension (MINC puts it first) becomes a ``TimeSeries`` at its step (seconds in MINC), a step read when it
  is shown; ``time_index=i`` reads one. A ``vector_dimension`` (RGB, displacement) gives components.
- Before any voxel is read, the data size is held against the file: a MINC 2 dataset may be compressed, so it must
  be one the file could inflate to.
- A MINC 1 file's netCDF header and MINC structure are checked before nibabel interprets them (issue #32: nibabel
  answered a damaged file with "IndexError: list index out of range" and the like): a header that does not parse is
  refused naming the part of the netCDF header (MINC 1 Programmer's Guide, "An Introduction to NetCDF") where it
  broke; a missing ``image`` variable, dimension variable, ``spacing`` / ``signtype`` attribute, or ``image-max`` /
  ``image-min`` pair is refused by name (Guide, "Image dimensions", "Image conversion variables").
"""
from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, file_size, read_bytes
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


#: nibabel's netCDF reader's steps, innermost first, and the part of a netCDF classic header each reads
_NETCDF_PARTS = (("_read_att_values", "an attribute's values"), ("_read_var", "a variable's record (name, "
                 "dimensions, attributes, type, size and offset)"), ("_read_att_array", "an attribute list"),
                 ("_read_gatt_array", "the global attributes"), ("_read_dim_array", "the dimension list"),
                 ("_read_var_array", "the variable list"), ("_read_numrecs", "the record count"))
_SIGNTYPES = (b"signed__", b"unsigned")


def _netcdf_part(exc: BaseException) -> str:
    """The part of the netCDF header nibabel's reader was in when ``exc`` stopped it."""
    names = set()
    tb = exc.__traceback__
    while tb is not None:
        names.add(tb.tb_frame.f_code.co_name)
        tb = tb.tb_next
    return next((part for name, part in _NETCDF_PARTS if name in names), "its header")


def _recording_netcdf_file() -> Any:
    """nibabel's netCDF reader, keeping each variable's header record (``records``: name, dimensions, shape,
    attributes, type code, item size, dtype, offset, size field), which it reads and then drops."""
    from nibabel.externals.netcdf import netcdf_file

    class Recording(netcdf_file):
        def _read_var(self) -> tuple:
            record = super()._read_var()
            self.__dict__.setdefault("records", []).append(record)
            return record
    return Recording


def _check_sizes(path: PathLike, records: list[tuple]) -> None:
    """Each variable's size field against its dimensions (netCDF classic: the product of the dimension lengths
    times the type's size, rounded up to 4 bytes; 2^32 - 1 for a variable over 4 GiB; issue #32: a flipped bit made
    ``zspace`` 7 instead of 6, and nibabel read the image's 240 bytes as 280, the next variable's bytes among them).
    Data past the end of the file already stops nibabel's reader (a header that does not parse)."""
    for name, dims, shape, _attrs, _code, item, _dtype, _begin, vsize in records:
        if shape and shape[0] is None:               # a record variable: its size is per record
            continue
        exact = int(np.prod(shape, dtype=object)) * item
        if vsize not in (exact, exact + (-exact % 4)) and not (vsize == 0xFFFFFFFF and exact > 0xFFFFFFFB):
            layout = " x ".join(f"{d} {n}" for d, n in zip(dims, shape)) or "a scalar"
            raise ReadError(path, f"MINC 1: variable {name!r} holds {exact} bytes by its dimensions ({layout} of "
                                  f"{item} bytes) but its size field says {vsize}: the header is damaged")


def check_minc1(path: PathLike) -> None:
    """ReadError in MINC's terms when a MINC 1 (netCDF classic) file's header does not parse or lacks what a MINC
    image needs (see the module)."""
    netcdf_file = _recording_netcdf_file()
    try:
        f = netcdf_file(str(path), "r", mmap=False) if file_size(path) < (64 << 20) else netcdf_file(str(path), "r")
    except Exception as exc:                    # noqa: BLE001 - any failure of the header parse is the file's
        raise ReadError(path, f"MINC 1: its netCDF header does not parse: {_netcdf_part(exc)} is damaged "
                              f"({type(exc).__name__}); the file is truncated or corrupt") from None
    try:
        _check_sizes(path, f.__dict__.get("records", []))
        variables = f.variables
        image = variables.get("image")
        if image is None:
            raise ReadError(path, f"MINC 1: no 'image' variable (the file holds {', '.join(variables) or 'none'})")
        for dim in image.dimensions:
            var = variables.get(dim)
            if var is None:
                raise ReadError(path, f"MINC 1: the image's dimension {dim!r} has no dimension variable")
            spacing = getattr(var, "spacing", None)
            if spacing != b"regular__":
                raise ReadError(path, f"MINC 1: dimension variable {dim!r} has spacing {spacing!r}; volviz reads "
                                      "'regular__' only (nibabel's MINC reader needs it)")
        if image.typecode() not in "fd" and getattr(image, "signtype", None) not in _SIGNTYPES:
            raise ReadError(path, f"MINC 1: the image's signtype is {getattr(image, 'signtype', None)!r}, not "
                                  "'signed__' or 'unsigned'")
        high, low = variables.get("image-max"), variables.get("image-min")
        if high is None or low is None:
            raise ReadError(path, "MINC 1: the image has no 'image-max' / 'image-min' pair (its value scaling)")
        dims, image_dims = tuple(high.dimensions), tuple(image.dimensions)
        if dims != tuple(low.dimensions) or dims != image_dims[:len(dims)] or len(dims) > len(image_dims) - 2:
            raise ReadError(path, f"MINC 1: image-max's dimensions {dims} and image-min's {tuple(low.dimensions)} "
                                  f"must be the same leading dimensions of the image's {image_dims}, without its "
                                  "last two")
    finally:
        with warnings.catch_warnings():          # mmap'ed (files over 64 MiB): the map goes with its last view
            warnings.simplefilter("ignore", RuntimeWarning)
            f.close()


def read_minc(path: PathLike, time_index: int | None = None,
              allow_nonfinite: bool = True) -> RegularVolume | TimeSeries:
    """A MINC volume, or its time dimension as a time series (see the module)."""
    if read_bytes(check_file(path), 4)[:3] == b"CDF":
        check_minc1(path)
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
