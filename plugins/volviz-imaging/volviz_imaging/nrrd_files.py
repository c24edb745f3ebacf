"""NRRD (.nrrd, or a detached .nhdr header with its data file) through pynrrd: raw, text, gzip and bzip2 data.

- Placement: ``space directions`` and ``space origin`` (else ``spacings``, else unit voxels) in the file's ``space``;
  LPS and LAS files (what ITK, 3D Slicer and DICOM tools write) are turned into RAS, then
  ``placement.aligned_volume`` aligns the grid.
- An axis without a space direction (``none``) is not spatial: its ``kind`` ``time`` makes a ``TimeSeries`` (one
  volume per sample); any other kind (vector, RGB-color, list ...) makes the components of one array.
- The header is read first and the data size it claims is checked against the file before any data is read.
"""
from __future__ import annotations

import zlib
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, file_size, require_bytes
from volviz.io.errors import PathLike, ReadError, human_bytes
from volviz.io.metaimage import DEFLATE_MAX_RATIO
from volviz.model import RegularVolume, TimeSeries

from volviz_imaging.placement import LPS_TO_RAS, aligned_volume

_TO_RAS = {"right-anterior-superior": np.eye(4), "ras": np.eye(4),
           "left-anterior-superior": np.diag([-1.0, 1.0, 1.0, 1.0]), "las": np.diag([-1.0, 1.0, 1.0, 1.0]),
           "left-posterior-superior": LPS_TO_RAS, "lps": LPS_TO_RAS}
_COMPRESSED = {"gzip": DEFLATE_MAX_RATIO, "gz": DEFLATE_MAX_RATIO, "bzip2": 50_000, "bz2": 50_000}
#: the NRRD type names pynrrd reads (the NRRD format's list), by bytes per sample
_TYPE_NAMES = {1: "signed char|int8|int8_t|uchar|unsigned char|uint8|uint8_t|block",
               2: "short|short int|signed short|signed short int|int16|int16_t|ushort|unsigned short|"
                  "unsigned short int|uint16|uint16_t",
               4: "int|signed int|int32|int32_t|uint|unsigned int|uint32|uint32_t|float",
               8: "longlong|long long|long long int|signed long long|signed long long int|int64|int64_t|ulonglong|"
                  "unsigned long long|unsigned long long int|uint64|uint64_t|double"}
_TYPE_SIZES = {name: size for size, names in _TYPE_NAMES.items() for name in names.split("|")}
_ENCODINGS = ("raw", "ascii", "ASCII", "text", "txt", *_COMPRESSED)


def _header(p: Path) -> dict[str, Any]:
    import nrrd

    try:
        with open(p, "rb") as fh:
            return dict(nrrd.read_header(fh))
    except (nrrd.NRRDError, ValueError, UnicodeDecodeError, KeyError, IndexError, TypeError) as exc:
        raise ReadError(p, f"not a NRRD header pynrrd can read ({exc})") from None


def _data_file(p: Path, header: dict[str, Any]) -> Path:
    name = header.get("data file") or header.get("datafile")
    if not name:
        return p
    if not isinstance(name, str) or " " in name.strip() or "%" in name or name.upper().startswith("LIST"):
        raise ReadError(p, "its 'data file' is a list or pattern of files, which volviz does not read; use one file")
    data = p.parent / name
    if not data.is_file():
        raise ReadError(p, f"its data file {name!r} is not beside it (looked for {data})")
    return data


def _check_size(p: Path, header: dict[str, Any]) -> None:
    missing = [f for f in ("dimension", "type", "encoding", "sizes") if f not in header]
    if missing:
        raise ReadError(p, f"NRRD header lacks the required field(s) {', '.join(missing)}")
    sizes = [int(n) for n in header.get("sizes", [])]
    if len(sizes) != int(header["dimension"]):
        raise ReadError(p, f"NRRD dimension is {header['dimension']} but sizes lists {len(sizes)} axes")
    if str(header.get("endian", "little")) not in ("little", "big"):
        raise ReadError(p, f"NRRD endian is {str(header['endian'])[:20]!r}, not little or big")
    if not sizes or any(n < 1 for n in sizes):
        raise ReadError(p, f"NRRD sizes {sizes} must all be positive")
    kind, encoding = str(header.get("type", "")), str(header.get("encoding", "raw"))
    if kind not in _TYPE_SIZES:
        raise ReadError(p, f"NRRD type {kind[:40]!r} is not a NRRD sample type (int8 ... uint64, float, double)")
    if encoding not in _ENCODINGS:
        raise ReadError(p, f"NRRD encoding {encoding[:40]!r} is not one volviz reads ({', '.join(_ENCODINGS)})")
    item = _TYPE_SIZES[kind]
    needed = int(np.prod(sizes, dtype=object)) * item
    data = _data_file(p, header)
    size = file_size(data)
    what = f"NRRD {'x'.join(map(str, sizes))} {kind} data"
    encoding = encoding.lower()
    if encoding in _COMPRESSED:
        if needed > _COMPRESSED[encoding] * size + 64:
            raise ReadError(p, f"{what} ({human_bytes(needed)}) is more than its {size} {encoding} bytes can "
                               "inflate to: the header is wrong")
    elif encoding == "raw" and data != p:
        require_bytes(data, needed, size, what)


def _affine(header: dict[str, Any], spatial: list[int]) -> np.ndarray:
    affine = np.eye(4)
    directions = header.get("space directions")
    if directions is not None:
        rows = np.asarray(directions, dtype=np.float64)
        vectors = rows[spatial][:, :3]
        affine[: vectors.shape[1], : len(spatial)] = vectors.T
    else:
        spacings = np.asarray(header.get("spacings", [1.0] * len(header["sizes"])), dtype=np.float64)
        steps = np.where(np.isfinite(spacings[spatial]) & (spacings[spatial] > 0), spacings[spatial], 1.0)
        affine[:3, :3] = np.diag(steps)
    origin = header.get("space origin")
    if origin is not None:
        origin = np.asarray(origin, dtype=np.float64)
        if np.all(np.isfinite(origin)):
            affine[: len(origin), 3] = origin[:3]
    space = str(header.get("space", "")).lower().removesuffix("-time")
    return _TO_RAS.get(space, np.eye(4)) @ affine


def _axes(p: Path, header: dict[str, Any]) -> tuple[list[int], int | None, str]:
    """(the spatial axes, the non-spatial axis or None, its kind)."""
    sizes = [int(n) for n in header["sizes"]]
    directions = header.get("space directions")
    kinds = [str(k).lower() for k in header.get("kinds", ["domain"] * len(sizes))]
    if directions is not None:
        rows = np.asarray(directions, dtype=np.float64)
        for i in range(len(sizes)):  # a vector of numbers, or "none" (all NaN): a part NaN is a damaged vector
            if not (np.all(np.isfinite(rows[i])) or np.all(np.isnan(rows[i]))):
                raise ReadError(p, f"NRRD space direction {i} is {rows[i].tolist()}: neither a vector of finite "
                                   "numbers nor 'none'")
        spatial = [i for i in range(len(sizes)) if np.all(np.isfinite(rows[i]))]
    else:
        spatial = [i for i in range(len(sizes)) if kinds[i] in ("domain", "space", "time") or len(sizes) <= 3]
        spatial = spatial[:3]
    other = [i for i in range(len(sizes)) if i not in spatial]
    if len(spatial) > 3 or len(other) > 1 or (len(spatial) < 2 and len(sizes) > 1):
        raise ReadError(p, f"a NRRD of {len(sizes)} axes ({', '.join(kinds)}): volviz reads 2 or 3 space axes with "
                           "at most one axis of components or time")
    return spatial, (other[0] if other else None), (kinds[other[0]] if other else "")


def read_nrrd(path: PathLike, allow_nonfinite: bool = True) -> RegularVolume | TimeSeries:
    """A NRRD file as a volume, with its non-spatial axis as components or time steps (see the module)."""
    import nrrd

    p = check_file(path)
    header = _header(p)
    _check_size(p, header)
    spatial, other, kind = _axes(p, header)
    try:
        data, _ = nrrd.read(str(p), index_order="F")
    except zlib.error as exc:
        raise ReadError(p, f"its {header['encoding']} data is damaged (zlib: {exc})") from None
    except nrrd.NRRDError as exc:  # pynrrd's own words are NRRD's
        raise ReadError(p, f"its {header['encoding']} data does not fit its header ({str(exc)[:200]})") from None
    except ValueError as exc:
        raise ReadError(p, f"its {header['encoding']} data ends within a sample: the data is truncated "
                           f"({str(exc)[:120]})") from None
    except (OSError, EOFError, TypeError, KeyError, IndexError) as exc:
        raise ReadError(p, f"its {header['encoding']} data could not be read ({type(exc).__name__}: "
                           f"{str(exc)[:200]})") from None
    order = spatial + ([other] if other is not None else [])
    data = np.transpose(data, order)
    while data.ndim < (4 if other is not None else 3):  # a 2D image: one slice
        data = np.expand_dims(data, len(spatial))
        spatial = spatial + [-1]
    affine = _affine(header, [a for a in spatial if a >= 0])
    name = Path(p).name.rsplit(".", 1)[0]
    if other is not None and kind == "time":
        frames: list[Any] = [aligned_volume(p, data[..., t], affine, name, allow_nonfinite=allow_nonfinite,
                                            warn=t == 0) for t in range(data.shape[-1])]
        return TimeSeries(np.arange(len(frames), dtype=np.float64), frames, source=str(p))
    return aligned_volume(p, data, affine, name, allow_nonfinite=allow_nonfinite)
