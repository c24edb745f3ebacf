"""``read``: any supported file, folder or numbered series into a ``volviz.model`` dataset.

Above the registry, the folder rules and the series module, which it puts together; ``volviz.io`` re-exports it.
It lives below the package's ``__init__`` so that no module of ``volviz.io`` imports the package back (issue #31:
the ``io`` -> ``io.raw`` -> ``io.series`` -> ``io`` circle): a series takes its member reader as an argument.
"""
from __future__ import annotations

import functools
import os
from typing import Any, Callable, Sequence

from volviz.io.errors import PathLike, ReadError
from volviz.io.folders import folder_target
from volviz.io.registry import call_reader, format_of, is_pattern
from volviz.io.series import lazy_series
from volviz.model import TimeSeries


def read(path: PathLike, isolate: bool | None = None, **options: Any):
    """Read any supported file (or a series pattern: a glob, ``name%02d.ext`` or a list) into a model dataset.

    The format comes from the reader registry (options, folder markers, the name, else the file's magic bytes).
    Options go to the format's reader (e.g. ``q=`` for PLOT3D, ``dims=, dtype=, byteorder=`` for raw files,
    ``vtk_compatible=`` for DEM, ``blocks=`` for multiblock files, ``allow_nonfinite=``). Raises ReadError for bad
    or unsupported files. Readers of native code (VTK, HDF5) run in a child process with memory and time limits, so
    a file that crashes them gives a ReadError too; ``isolate=False`` (or ``VOLVIZ_ISOLATE=0``) reads in-process,
    for debugging (``volviz.io.isolated``).
    """
    if is_pattern(path):
        return lazy_series(path, functools.partial(read, isolate=isolate), **options)
    try:
        kind = format_of(path, options)
    except ReadError:
        target = folder_target(path) if os.path.isdir(path) else None
        if target is None:
            raise
        return read(target, isolate, **options)      # a folder of output: its collection file or numbered series
    return call_reader(kind, path, options, isolate)


def read_series(paths_or_pattern: str | PathLike | Sequence[PathLike], reader: Callable[..., object] | None = None,
                times: Sequence[float] | None = None, **options: Any) -> TimeSeries:
    """A TimeSeries of every file of a numbered series (a list, a glob or a printf pattern), read lazily with
    ``reader`` (default ``read``); ``volviz.io.series.lazy_series`` says how the files are ordered and timed."""
    return lazy_series(paths_or_pattern, reader or read, times, **options)
