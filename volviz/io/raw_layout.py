"""The layout of headerless binary data, guessed from its bytes: what File > Open offers for a ``.raw`` file or a
stack of numbered slices instead of asking the user to write a header by hand (the approach of 3D Slicer's
RawImageGuess and ImageJ's raw import, with the guess made for them).

Real volumes are smooth: a sample is much closer to its neighbours than to a sample far away. Each choice is scored
by that contrast -- 1 - mean |a[i + offset] - a[i]| / mean |a[i] - a[j]| for j far from i -- computed on an even sample
of the data, and the choices are made one after the other (each fixes what the next score needs):

1. the sample type and byte order, from neighbours along x (offset 1): a wrong byte order or type cuts the values
   into unrelated bytes (a signed type goes before its unsigned twin when its values span less than half the range:
   negative values read unsigned wrap to the top of the type);
2. the row length nx, from neighbours along y (offset nx), over the divisors of the sample count;
3. the slice height ny, from neighbours along z (offset nx ny) for a single file; a stack's files are its slices.

A size that is not a whole number of samples leaves its remainder as a header at the start; any other header is set
in the app's dialog, whose preview shows when the rows line up.
The result is a list, best sample type first; the user confirms or corrects it, and ``write_header`` writes it down
as a MetaImage header beside the data, which then opens like any other file.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from volviz.io._checks import file_size, read_at
from volviz.io.atomic import atomic_write_text
from volviz.io.errors import PathLike, ReadError
from volviz.io.registry import spec_of

#: the sample types tried, with their MetaImage names
SAMPLE_TYPES = {"uint8": "MET_UCHAR", "int8": "MET_CHAR", "uint16": "MET_USHORT", "int16": "MET_SHORT",
                "uint32": "MET_UINT", "int32": "MET_INT", "float32": "MET_FLOAT", "float64": "MET_DOUBLE"}
MIN_SIDE, MAX_SIDE = 8, 16384       # a row or slice side outside these is not considered
MAX_HEADER = 4096                   # the largest header taken as the remainder of an odd size
SAMPLE_BYTES = 4 << 20              # the bytes read for the scores (from the middle of the data)


@dataclass(frozen=True)
class RawLayout:
    """How headerless data is laid out: ``dims`` (nx, ny, nz), x fastest; for a stack nz is the number of files."""

    dims: tuple[int, int, int]
    dtype: str
    byteorder: str = "little"
    header_bytes: int = 0
    score: float = 0.0

    @property
    def itemsize(self) -> int:
        return np.dtype(self.dtype).itemsize

    def disk_dtype(self) -> np.dtype:
        dt = np.dtype(self.dtype)
        return dt.newbyteorder("<" if self.byteorder == "little" else ">") if dt.itemsize > 1 else dt


def contrast(values: np.ndarray, offset: int) -> float:
    """1 - (mean difference of samples ``offset`` apart) / (mean difference of samples far apart): near 1 for a smooth
    field along that offset, near 0 (or below) for unrelated samples; 0 when it cannot be told."""
    v = values[np.isfinite(values)] if values.dtype.kind == "f" else values
    v = v.astype(np.float64)
    if offset <= 0 or v.size < 2 * offset + 16:
        return 0.0
    with np.errstate(over="ignore", invalid="ignore"):     # the huge values of a wrong float type
        near = float(np.mean(np.abs(v[offset:] - v[:-offset])))
        far = float(np.mean(np.abs(v - np.roll(v, v.size // 2 + 7))))
    if not (np.isfinite(near) and np.isfinite(far)) or far <= 0:
        return 0.0
    return 1.0 - near / far


def _divisors(n: int) -> list[int]:
    small = [d for d in range(1, int(math.isqrt(n)) + 1) if n % d == 0]
    return sorted(set(small + [n // d for d in small]))


def _samples(path: Path, offset: int, length: int, disk: np.dtype) -> np.ndarray:
    """Up to ``SAMPLE_BYTES`` whole samples from the middle of ``length`` bytes at ``offset``, as native values."""
    take = min(length, SAMPLE_BYTES) // disk.itemsize * disk.itemsize
    start = offset + ((length - take) // 2) // disk.itemsize * disk.itemsize
    raw = read_at(path, start, take)
    return np.frombuffer(bytes(raw), dtype=disk).astype(disk.newbyteorder("="))


def _types(path: Path, size: int) -> list[tuple[Any, ...]]:
    """``(score along x, dtype, byte order, header bytes)`` for every sample type whose size fits the file."""
    found = []
    for dtype in SAMPLE_TYPES:
        item = np.dtype(dtype).itemsize
        header = size % item if size % item <= MAX_HEADER else -1
        if header < 0 or size - header < item * MIN_SIDE:
            continue
        for order in (("little", "big") if item > 1 else ("little",)):
            disk = np.dtype(dtype).newbyteorder("<" if order == "little" else ">") if item > 1 else np.dtype(dtype)
            values = _samples(path, header, size - header, disk)
            if values.dtype.kind == "f" and not np.isfinite(values).mean() > 0.99:
                continue                            # floats of the wrong type or order are NaN and Inf
            found.append((contrast(values, 1), dtype, order, header, _spread(values)))
    found.sort(key=lambda t: -t[0])
    for i, (_, dtype, order, _, spread) in enumerate(found):   # signed data read unsigned spans the whole type
        signed = next((j for j, t in enumerate(found) if t[1] == "int" + dtype[4:] and t[2] == order), None) \
            if dtype.startswith("uint") else None
        if signed is not None and signed > i and found[signed][4] < 0.5 * spread:
            found.insert(i, found.pop(signed))
    return [t[:4] for t in found]


def _spread(values: np.ndarray) -> float:
    """The range of integer samples as a share of their type's range (0 for floats)."""
    if values.dtype.kind not in "ui" or values.size == 0:
        return 0.0
    info = np.iinfo(values.dtype)
    return float(int(values.max()) - int(values.min())) / float(int(info.max) - int(info.min))


def _best_side(values: np.ndarray, count: int, stride: int, candidates: list[int]) -> tuple[int, float]:
    """The candidate row length (or slice height) whose neighbours ``stride * side`` apart are most alike."""
    best, score = candidates[0] if candidates else count, -math.inf
    for side in candidates:
        s = contrast(values, stride * side)
        if s > score + 1e-3:
            best, score = side, s
    return best, score


def _geometry(values: np.ndarray, count: int, n_files: int) -> tuple[tuple[int, int, int], list[float]]:
    """The sides (and their contrasts along y, z) of ``count`` samples per file: a volume for one file, a slice of
    a stack otherwise."""
    if n_files > 1:
        rows = [d for d in _divisors(count) if MIN_SIDE <= d <= MAX_SIDE and MIN_SIDE <= count // d <= MAX_SIDE]
        nx, y_score = _best_side(values, count, 1, rows)
        return (nx, count // nx, n_files), [y_score]
    rows = [d for d in _divisors(count) if MIN_SIDE <= d <= MAX_SIDE and count // d >= MIN_SIDE]
    nx, y_score = _best_side(values, count, 1, rows)
    rest = count // nx
    heights = [d for d in _divisors(rest) if MIN_SIDE <= d <= MAX_SIDE]
    ny, z_score = _best_side(values, rest, nx, heights) if heights else (rest, 0.0)
    return (nx, ny, rest // ny), [y_score, z_score]


def guess_layouts(paths: Sequence[PathLike], limit: int = 5) -> list[RawLayout]:
    """The likeliest layouts of headerless data, best first: one file (a volume) or several files of equal size
    (the slices of a stack, in the order given). ReadError when no layout fits the sizes."""
    files = [Path(p) for p in paths]
    if not files:
        raise ValueError("no files given")
    size = file_size(files[0])
    if len(files) > 1 and any(file_size(f) != size for f in files[1:]):
        raise ReadError(files[0], "the slices of the stack differ in size; a headerless stack has equal slices")
    layouts: list[RawLayout] = []
    probe = files[len(files) // 2]          # a stack's middle slice: its first ones are often empty
    for x_score, dtype, order, header in _types(probe, size)[:4]:
        item = np.dtype(dtype).itemsize
        values = _samples(probe, header, size - header, RawLayout((1, 1, 1), dtype, order).disk_dtype())
        dims, scores = _geometry(values, (size - header) // item, len(files))
        if min(dims) >= 1:
            layouts.append(RawLayout(dims, dtype, order, header, float(np.mean([x_score, *scores]))))
    if not layouts:
        raise ReadError(files[0], f"its size ({size} bytes) fits no headerless layout volviz can guess")
    return layouts[:limit]          # in the order of the sample types' scores: the type is the first decision


def metaimage_header(layout: RawLayout, data_files: Sequence[str], spacing: Sequence[float] = (1.0, 1.0, 1.0)) -> str:
    """A MetaImage (.mhd) header describing ``layout``: the one data file by name, or a stack's files as a LIST."""
    lines = ["ObjectType = Image", "NDims = 3", f"DimSize = {' '.join(map(str, layout.dims))}",
             f"ElementType = {SAMPLE_TYPES[layout.dtype]}",
             f"ElementSpacing = {' '.join(f'{float(s):g}' for s in spacing)}",
             f"BinaryDataByteOrderMSB = {'True' if layout.byteorder == 'big' else 'False'}"]
    if layout.header_bytes:
        lines.append(f"HeaderSize = {layout.header_bytes}")
    if len(data_files) == 1:
        lines.append(f"ElementDataFile = {data_files[0]}")
    else:
        lines.append("ElementDataFile = LIST")
        lines += list(data_files)
    return "\n".join(lines) + "\n"


def headerless_data(path: PathLike) -> list[Path] | None:
    """The files of headerless data that ``path`` belongs to -- a ``.raw`` file without a MetaImage header beside
    it, or one of a stack of numbered slices of equal size (``quarter.1`` ... ``quarter.93``, by number) -- or None
    when volviz reads the file by itself (or it is something else)."""
    p = Path(path)
    if not p.is_file():
        return None
    try:
        spec_of(p)
        return None
    except ReadError:
        pass
    if p.suffix.lower() == ".raw":
        return None if any(p.parent.glob(p.stem + ".mh[da]")) else [p]
    numbered = re.fullmatch(r"(.*\.)(\d+)", p.name)
    if numbered is None:
        return None
    stem, size = numbered.group(1), p.stat().st_size
    siblings = [(int(m.group(1)), q) for q in p.parent.iterdir()
                if (m := re.fullmatch(re.escape(stem) + r"(\d+)", q.name)) and q.is_file() and q.stat().st_size == size]
    return [q for _, q in sorted(siblings)]


def layout_problem(files: Sequence[PathLike], layout: RawLayout) -> str | None:
    """Why ``layout`` does not fit the files' sizes (None when it does)."""
    nx, ny, nz = layout.dims
    if min(layout.dims) < 1:
        return "every size must be at least 1"
    stack = len(files) > 1
    if stack and nz != len(files):
        return f"the stack has {len(files)} slice files, not {nz}"
    per_file = layout.header_bytes + nx * ny * (1 if stack else nz) * layout.itemsize
    size = file_size(files[0])
    if per_file != size:
        what = "each slice file" if stack else "the file"
        return f"{nx} x {ny}{'' if stack else f' x {nz}'} {layout.dtype} samples need {per_file} bytes, {what} " \
               f"holds {size}"
    return None


def layout_slice(files: Sequence[PathLike], layout: RawLayout, k: int) -> np.ndarray:
    """Slice ``k`` (nx, ny) of data laid out as ``layout`` (which must fit: ``layout_problem`` is None)."""
    nx, ny, nz = layout.dims
    disk = layout.disk_dtype()
    plane = nx * ny * disk.itemsize
    path, offset = (Path(files[k]), layout.header_bytes) if len(files) > 1 else \
        (Path(files[0]), layout.header_bytes + k * plane)
    values = np.frombuffer(bytes(read_at(path, offset, plane)), dtype=disk).astype(disk.newbyteorder("="))
    return values.reshape((nx, ny), order="F")


def preview_image(values: np.ndarray) -> np.ndarray:
    """A slice (nx, ny) as 8-bit grey levels (ny rows, y up: row 0 is the largest y) between its 1 % and 99 %
    percentiles, for a preview of a guessed layout; non-finite samples black."""
    v = np.asarray(values, dtype=np.float64)
    finite = v[np.isfinite(v)]
    lo, hi = (float(x) for x in np.percentile(finite, [1.0, 99.0])) if finite.size else (0.0, 1.0)
    scaled = np.where(np.isfinite(v), (v - lo) / (hi - lo if hi > lo else 1.0), 0.0)
    return np.ascontiguousarray((np.clip(scaled, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8).T[::-1])


def write_header(files: Sequence[PathLike], layout: RawLayout, spacing: Sequence[float],
                 fallback_folder: PathLike) -> Path:
    """Write the MetaImage header of ``layout`` beside the data (``quarter.mhd`` for ``quarter.1`` ...,
    ``head.mhd`` for ``head.raw``), naming the data files relative to it; where that folder is not writable, in
    ``fallback_folder`` naming them by absolute path. Written atomically; returns the header's path."""
    first = Path(files[0])
    stem = re.sub(r"\.\d+$", "", first.name) if len(files) > 1 else first.stem
    folder = first.parent
    if os.access(folder, os.W_OK):
        names = [Path(f).name for f in files]
    else:
        folder = Path(fallback_folder)
        folder.mkdir(parents=True, exist_ok=True)
        names = [str(Path(f).resolve()) for f in files]
    target = folder / f"{stem.rstrip('.') or 'volume'}.mhd"
    atomic_write_text(target, metaimage_header(layout, names, spacing))
    return target
