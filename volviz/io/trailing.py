"""Bytes after the data a header describes (issue #32): a header that claims less than the file holds is refused,
naming the header's fields and both sizes, when the extra bytes make at least one more slice of the data (the header
was changed or damaged: reading it would reinterpret the voxels); fewer extra bytes (padding, a stale trailer) are
read past with a :class:`ReadWarning` the user sees, never silently."""
from __future__ import annotations

import warnings

from volviz.io.errors import PathLike, ReadError, ReadWarning

__all__ = ["check_trailing"]


def check_trailing(path: PathLike, fields: str, data_bytes: int, extra: int, slice_bytes: int) -> None:
    """``extra`` bytes follow the ``data_bytes`` of data that the header's ``fields`` (e.g. ``"shape (15, 14, 12)
    of float32"``) describe; ``slice_bytes``: the bytes of one slice along the data's slowest axis."""
    if extra <= 0:
        return
    if extra >= max(slice_bytes, 1):
        raise ReadError(path, f"its header gives {fields}: {data_bytes} bytes of data, but the file holds {extra} "
                              f"bytes more ({data_bytes + extra} in all; one slice is {slice_bytes} bytes): the "
                              "header claims less data than the file holds")
    warnings.warn(f"{path}: {extra} bytes follow the {data_bytes} bytes of data that its header gives ({fields}); "
                  "they are ignored", ReadWarning, stacklevel=3)
