"""Multi-page TIFF stacks (microscopy z-stacks: ImageJ hyperstacks, OME-TIFF, plain page sequences) -> a volume,
through tifffile. ``volviz.io.image.read_image`` asks here first for every TIFF; a file whose pages do not make a
stack (one page, an RGB photo) goes on to the 2D image path.

- Axes, from tifffile's series: Y and X are the image; a depth axis (Z, else ImageJ's / tifffile's generic I or Q)
  of more than one page makes the volume's z; channels (C) and samples (S: RGB) become the components of one array
  (by magnitude or one channel in the array selector); a time axis (T) makes a ``TimeSeries``. Other axes of more
  than one entry are refused with their names.
- Voxel size: OME-XML's PhysicalSizeX/Y/Z; else the X/YResolution tags (pixels per unit) and ImageJ's ``spacing``
  for z; 1 where the file says nothing. Sizes are in the file's unit (ImageJ's ``unit``, OME's
  PhysicalSizeXUnit, e.g. micrometres); no conversion.
- Orientation: x along the image's columns, y up the image (row 0, the top row, at the largest y, as the 2D image
  is shown), z from the first page to the last.
- Before pixels are read, the stack's size is checked against the file: an uncompressed stack must fit in it, a
  compressed one must not claim more than ``MAX_RATIO`` times the file's bytes.
"""
from __future__ import annotations

import contextlib
import logging
import mmap
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from volviz.io._checks import check_finite, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError, human_bytes
from volviz.io.tiffcheck import check_tiff
from volviz.model import RegularVolume, TimeSeries
from volviz.model.arrays import volume_of

TIFF_MAGIC = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")
MAX_RATIO = 4096       # what LZW / deflate / packbits can inflate to, per byte of the file, with room
_DEPTH = ("Z", "I", "Q")
_COMPONENTS = ("C", "S")


def is_tiff(head: bytes) -> bool:
    return head[:4] in TIFF_MAGIC


def _layout(path: PathLike, axes: str, shape: tuple[int, ...]) -> dict[str, int] | None:
    """Where the time, depth and component axes are (-1: none), or None when the pages make no stack."""
    sizes = dict(zip(axes, shape))
    if "Y" not in sizes or "X" not in sizes:
        return None
    depth = [a for a in _DEPTH if sizes.get(a, 1) > 1]
    if not depth:
        return None
    components = [a for a in _COMPONENTS if sizes.get(a, 1) > 1]
    other = [a for a in axes if a not in "TYX" + "".join(_DEPTH + _COMPONENTS) and sizes[a] > 1]
    if len(depth) > 1 or len(components) > 1 or other:
        extra = depth[1:] + components[1:] + other
        raise ReadError(path, f"a TIFF stack with axes {axes} {'x'.join(map(str, shape))}: volviz reads one depth "
                              f"axis, one channel axis and a time axis; the axes {', '.join(extra)} are more")
    return {"T": axes.find("T") if sizes.get("T", 1) > 1 else -1, "Z": axes.index(depth[0]),
            "C": axes.index(components[0]) if components else -1}


def _resolution(page: Any, tag: str) -> float | None:
    """Microns (or the file's unit) per pixel from a resolution tag in pixels per unit."""
    entry = page.tags.get(tag)
    if entry is None:
        return None
    value = entry.value
    try:
        per_unit = value[0] / value[1] if isinstance(value, tuple) else float(value)
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return 1.0 / per_unit if np.isfinite(per_unit) and per_unit > 0 else None


def _positive(value: Any) -> float | None:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if np.isfinite(v) and v > 0 else None


def _spacing(tif: Any) -> tuple[float, float, float]:
    page = tif.pages[0]
    sx, sy = _resolution(page, "XResolution"), _resolution(page, "YResolution")
    sz = _positive((tif.imagej_metadata or {}).get("spacing")) if tif.is_imagej else None
    if tif.is_ome:
        # heavy: tifffile (about 15 modules), loaded only when a TIFF stack is read
        import tifffile

        try:
            pixels = tifffile.xml2dict(tif.ome_metadata)["OME"]["Image"]
            pixels = (pixels[0] if isinstance(pixels, list) else pixels)["Pixels"]
            sx = _positive(pixels.get("PhysicalSizeX")) or sx
            sy = _positive(pixels.get("PhysicalSizeY")) or sy
            sz = _positive(pixels.get("PhysicalSizeZ")) or sz
        except (KeyError, TypeError, IndexError, ValueError):
            pass
    return sx or 1.0, sy or sx or 1.0, sz or 1.0


def _pages(indices: list[int]) -> str:
    """``"1-2, 4-6"``: 1-based page numbers as runs."""
    runs: list[list[int]] = []
    for i in sorted(indices):
        if runs and i == runs[-1][1] + 1:
            runs[-1][1] = i
        else:
            runs.append([i, i])
    return ", ".join(f"{a + 1}" if a == b else f"{a + 1}-{b + 1}" for a, b in runs)


def check_one_stack(path: PathLike, tif: Any) -> None:
    """Refuse pages of the stack's size and type that tifffile puts in a series of their own: their tags differ
    from the stack's (a damaged tag type or code, issue #32), and reading the first series would leave them out
    without a word, or read one page as an image. Files whose metadata defines the series (OME, ImageJ) and pages
    of another size (thumbnails, masks) are not concerned."""
    first = tif.series[0]
    if len(tif.series) < 2 or first.kind not in ("generic", "shaped", "uniform") or first.keyframe is None:
        return
    alike = [s for s in tif.series if s.kind == first.kind and s.keyframe is not None
             and s.keyframe.shape == first.keyframe.shape and s.dtype == first.dtype]
    if len(alike) > 1:
        groups = "; ".join(_pages([p.index for p in s.pages if p is not None]) for s in alike)
        h, w = first.keyframe.shape[:2]
        split = alike[1].keyframe
        raise ReadError(path, f"its pages are {h}x{w} {first.dtype} images alike, but their tags split them into "
                              f"{len(alike)} stacks (pages {groups}; tags that differ: "
                              f"{_tag_differences(_neighbour(tif, split), split)}): the file is damaged or mixes "
                              "stacks")


def _neighbour(tif: Any, page: Any) -> Any:
    """The page before ``page`` in the file (the one after it for the first), with its tags."""
    other = tif.pages[page.index - 1 if page.index else page.index + 1]
    return other if hasattr(other, "tags") else tif.series[0].keyframe


def _tag_differences(a: Any, b: Any) -> str:
    """``"Compression (SHORT 1 / BYTE b'\\x01')"``: the tags two pages hold with another type or value."""
    def tags(page: Any) -> dict[int, Any]:
        return {t.code: t for t in page.tags.values()}

    ta, tb = tags(a), tags(b)
    out = []
    for code in sorted(set(ta) | set(tb)):
        x, y = ta.get(code), tb.get(code)
        if code in (270, 273, 305, 324) or (x is not None and y is not None and x.dtype == y.dtype
                                       and repr(x.value) == repr(y.value)):
            continue  # strip and tile offsets differ from page to page; description and software: the first only
        show = lambda t: "none" if t is None else f"{t.dtype.name} {t.value!r}"[:40]  # noqa: E731
        out.append(f"{(x or y or ta[code]).name} ({show(x)} / {show(y)})")
    return ", ".join(out[:4]) or "none of the usual ones"


def _check_size(path: PathLike, series: Any, tif: Any) -> None:
    needed = int(np.prod(series.shape, dtype=object)) * np.dtype(series.dtype).itemsize
    size = file_size(path)
    compressed = int(getattr(tif.pages[0], "compression", 1)) != 1
    limit = MAX_RATIO * size if compressed else size
    if needed > limit:
        raise ReadError(path, f"its pages claim a {'x'.join(map(str, series.shape))} {series.dtype} stack "
                              f"({human_bytes(needed)}), more than its {size} "
                              f"{'compressed ' if compressed else ''}bytes can hold: the file is damaged")


def _volume(path: PathLike, stack: np.ndarray, spacing: tuple[float, float, float], name: str,
            allow_nonfinite: bool) -> RegularVolume:
    """(z, y, x[, c]) pages, row 0 at the top -> a volume (x, y up, z[, c])."""
    data = np.moveaxis(stack, (0, 1, 2), (2, 1, 0))[:, ::-1]
    check_finite(path, data, allow_nonfinite)
    return volume_of(data, name, spacing, source=str(path))


class _Complaints(logging.Handler):
    """What tifffile logs about a file while it reads it (an invalid page offset, corrupted ImageJ metadata)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


@contextlib.contextmanager
def _complaints() -> Iterator[_Complaints]:
    logger = logging.getLogger("tifffile")
    handler, propagate = _Complaints(), logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield handler
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate


def read_tiff_stack(path: PathLike, allow_nonfinite: bool = True) -> RegularVolume | TimeSeries | None:
    """The TIFF's stack as a volume (or a time series of them), or None when its pages make no stack. A file
    tifffile finds damaged (it logs a warning: a page beyond the end, corrupted ImageJ metadata) is refused, whatever
    its first page holds."""
    # heavy: tifffile (about 15 modules), loaded only when a TIFF stack is read
    import tifffile

    if file_size(path) < 8:
        check_tiff(Path(path), read_bytes(path))
    else:
        with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
            check_tiff(Path(path), data)  # tifffile trusts the directory: IndexError, ZeroDivisionError, zlib's words
    with _complaints() as complaints:
        result = _read(path, allow_nonfinite, tifffile)
    if complaints.messages:
        found = complaints.messages[0].split("> ", 1)[-1]
        raise ReadError(path, f"is a damaged TIFF ({found}; {len(complaints.messages)} problem(s) found)")
    return result


def _read(path: PathLike, allow_nonfinite: bool, tifffile: Any) -> RegularVolume | TimeSeries | None:
    try:
        with tifffile.TiffFile(str(path)) as tif:
            if not tif.series:
                return None
            check_one_stack(path, tif)
            series = tif.series[0]
            layout = _layout(path, series.axes, tuple(series.shape))
            if layout is None:
                return None
            _check_size(path, series, tif)
            spacing = _spacing(tif)
            interval = _positive((tif.imagej_metadata or {}).get("finterval")) if tif.is_imagej else None
            data = series.asarray()
    except ReadError:
        raise
    except (tifffile.TiffFileError, ValueError, OSError, EOFError, KeyError, IndexError, TypeError,
            MemoryError) as exc:
        raise ReadError(path, f"not a readable TIFF stack ({type(exc).__name__}: {str(exc)[:200]})") from None
    axes = series.axes
    order = [layout["T"]] if layout["T"] >= 0 else []
    order += [layout["Z"], axes.index("Y"), axes.index("X")] + ([layout["C"]] if layout["C"] >= 0 else [])
    rest = [i for i in range(data.ndim) if i not in order]       # axes of one entry
    data = np.transpose(data, rest + order).reshape([data.shape[i] for i in order])
    name = "intensity"
    if layout["T"] < 0:
        return _volume(path, data, spacing, name, allow_nonfinite)
    frames: list[Any] = [_volume(path, data[t], spacing, name, allow_nonfinite) for t in range(len(data))]
    return TimeSeries(np.arange(len(frames)) * (interval or 1.0), frames, source=str(path))
