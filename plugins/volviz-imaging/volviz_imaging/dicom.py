"""DICOM series (a folder of slices, one slice of the series, or a multi-frame file) through pydicom.

- Which files: opening a file reads the series it belongs to (same SeriesInstanceUID) from its folder; opening a
  folder reads its files (and its subfolders' when it holds a DICOMDIR), and shows the series with the most
  slices, naming the others in a warning; ``series="<SeriesInstanceUID or SeriesNumber or description>"`` picks
  one. Files without pixel data (reports, RT plans) and files that are not DICOM are skipped.
- Geometry: slices are ordered along the normal of their ImageOrientationPatient by their ImagePositionPatient,
  spaced by the distance between them (unequal gaps are reported, and the mean gap is used); PixelSpacing sets the
  in-plane size. Patient space (LPS) is turned into RAS and aligned by ``placement.aligned_volume``. Slices without
  position (secondary captures, legacy multi-frame files) are stacked by InstanceNumber at SpacingBetweenSlices
  (else SliceThickness, else 1).
- A folder whose slices repeat each position the same number of times (cardiac phases, dynamic series) becomes a
  ``TimeSeries`` of volumes, ordered by TriggerTime / AcquisitionTime / InstanceNumber within a position.
- Values through the modality LUT (RescaleSlope / RescaleIntercept: CT in Hounsfield units); RGB slices give one
  array of three components. Compressed pixel data is decoded by pydicom's decoders: RLE natively, and through GDCM
  (python-gdcm) JPEG Lossless (Process 14, the usual PACS export), JPEG-LS, JPEG 2000 and JPEG baseline; 12-bit JPEG
  Extended needs pylibjpeg-libjpeg (GPL, not installed). A transfer syntax no installed decoder handles is named in
  the error.
"""
from __future__ import annotations

import contextlib
import logging
import os
import warnings
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from volviz.io._checks import read_bytes
from volviz.io.errors import ChoiceWarning, PathLike, ReadError, ReadWarning
from volviz.model import RegularVolume, TimeSeries

from volviz_imaging.placement import aligned_volume, lps_to_ras
from volviz_imaging.specs import is_dicom

MAX_FILES = 20_000          # files of a folder looked at
_HEADER_TAGS = ("SOPInstanceUID", "SeriesInstanceUID", "SeriesNumber", "SeriesDescription", "Modality", "Rows",
                "Columns", "ImagePositionPatient", "ImageOrientationPatient", "PixelSpacing", "InstanceNumber",
                "NumberOfFrames", "TriggerTime", "AcquisitionTime", "SpacingBetweenSlices", "SliceThickness",
                "SamplesPerPixel", "DoseGridScaling", "GridFrameOffsetVector", "RescaleIntercept", "RescaleType",
                "DoseUnits", "PixelData", "FloatPixelData", "DoubleFloatPixelData")


@dataclass
class _Slice:
    path: Path
    uid: str
    series: str
    number: str
    description: str
    quantity: str
    shape: tuple[int, int]
    frames: int
    position: np.ndarray | None
    orientation: np.ndarray | None
    spacing: tuple[float, float]
    instance: int
    time: float
    gap: float


def _floats(value: Any, n: int) -> np.ndarray | None:
    try:
        out = np.asarray([float(v) for v in value], dtype=np.float64)
    except (TypeError, ValueError):
        return None
    return out if out.shape == (n,) and np.all(np.isfinite(out)) else None


def _number(value: Any, default: float) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        return default
    return out if np.isfinite(out) else default


def _quantity(ds: Any) -> str:
    """What the values are, for the array's name: the modality and the unit the modality LUT gives ("CT (HU)",
    "RTDOSE (GY)"), else the modality ("MR"), else "intensity"."""
    modality = str(ds.get("Modality", "") or "").strip()
    unit = str(ds.get("DoseUnits", "") or ds.get("RescaleType", "") or "").strip()
    if not unit and modality == "CT" and "RescaleIntercept" in ds:
        unit = "HU"
    if modality and unit:
        return f"{modality} ({unit})"
    return modality or "intensity"


def _header(path: Path) -> _Slice | None:
    """The geometry of one file, or None when it is not a DICOM image."""
    import pydicom
    from pydicom.errors import BytesLengthException, InvalidDicomError

    try:
        ds = pydicom.dcmread(path, stop_before_pixels=False, specific_tags=list(_HEADER_TAGS), defer_size=256)
    except (InvalidDicomError, OSError, ValueError, EOFError, KeyError, TypeError, AttributeError):
        return None
    try:
        return _slice_of(path, ds)
    except (BytesLengthException, NotImplementedError, ValueError, TypeError, KeyError, IndexError,
            OverflowError) as exc:  # pydicom converts a deferred value when it is first used
        raise ReadError(path, f"a DICOM header element is damaged ({type(exc).__name__}: "
                              f"{str(exc).split('. ')[0][:160]})") from None


def _slice_of(path: Path, ds: Any) -> _Slice | None:
    if not any(t in ds for t in ("PixelData", "FloatPixelData", "DoubleFloatPixelData")) or "Rows" not in ds:
        return None
    spacing = _floats(ds.get("PixelSpacing"), 2)
    gap = _number(ds.get("SpacingBetweenSlices"), 0.0) or _number(ds.get("SliceThickness"), 0.0)
    return _Slice(path, str(ds.get("SOPInstanceUID", "")) or str(path), str(ds.get("SeriesInstanceUID", "")),
                  str(ds.get("SeriesNumber", "")),
                  str(ds.get("SeriesDescription", "") or ds.get("Modality", "")), _quantity(ds),
                  (int(ds.Rows), int(ds.get("Columns", 0))), max(int(_number(ds.get("NumberOfFrames"), 1)), 1),
                  _floats(ds.get("ImagePositionPatient"), 3), _floats(ds.get("ImageOrientationPatient"), 6),
                  (float(spacing[0]), float(spacing[1])) if spacing is not None and np.all(spacing > 0) else (1.0, 1.0),
                  int(_number(ds.get("InstanceNumber"), 0)),
                  _number(ds.get("TriggerTime"), _number(ds.get("AcquisitionTime"), 0.0)), gap if gap > 0 else 1.0)


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """pydicom's warnings and log messages about other files' metadata quirks (an implicit VR where explicit was
    announced, a malformed IS value) are not the user's business while a folder is scanned or pixels decoded."""
    logger = logging.getLogger("pydicom")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", module=r"pydicom(\.|$)")
            yield
    finally:
        logger.setLevel(level)


def _unique(slices: list[_Slice], chosen: Path | None) -> list[_Slice]:
    """One file per SOPInstanceUID (copies of one image in other encodings): the opened file's, else the first."""
    seen: dict[str, _Slice] = {}
    for s in sorted(slices, key=lambda s: (s.path != chosen, str(s.path))):
        seen.setdefault(s.uid, s)
    return sorted(seen.values(), key=lambda s: str(s.path))


def _candidates(p: Path) -> tuple[Path, list[Path], Path | None]:
    """(the folder, its files to look at, the file the user opened or None)."""
    if p.is_dir():
        folder, chosen = p, None
        deep = (p / "DICOMDIR").exists()
    else:
        folder, chosen, deep = p.parent, p, False
    files: list[Path] = []
    walker = os.walk(folder) if deep else [(str(folder), [], sorted(os.listdir(folder)))]
    for root, dirs, names in walker:
        dirs.sort()
        for name in sorted(names):
            f = Path(root) / name
            if name.startswith(".") or name.upper() == "DICOMDIR" or not f.is_file():
                continue
            files.append(f)
            if len(files) > MAX_FILES:
                raise ReadError(folder, f"holds more than {MAX_FILES} files; open one file of the series instead")
    return folder, files, chosen


def _series_key(s: _Slice) -> str:
    return s.series or f"(no series UID) {s.shape}"


def _pick_series(path: Path, slices: list[_Slice], chosen: Path | None, series: str | None) -> list[_Slice]:
    groups: dict[str, list[_Slice]] = defaultdict(list)
    for s in slices:
        groups[_series_key(s)].append(s)

    def label(key: str) -> str:
        first = groups[key][0]
        return f"{first.number or '?'} {first.description!r} ({len(groups[key])} files, UID {key})"

    if series is not None:
        hits = [k for k, g in groups.items() if series in (k, g[0].number, g[0].description)]
        if not hits:
            raise ReadError(path, f"no series {series!r}; the series here are: "
                                  + "; ".join(label(k) for k in groups))
        key, how = hits[0], "as asked"
    elif chosen is not None:
        mine = next((s for s in slices if s.path == chosen), None)
        if mine is None:
            raise ReadError(chosen, "is not a DICOM image (no pixel data, or not a DICOM file pydicom can read)")
        key, how = _series_key(mine), "of the file opened"
    else:
        key, how = max(groups, key=lambda k: len(groups[k])), "with the most files"
    if len(groups) > 1:
        keys = sorted(groups, key=lambda k: -len(groups[k]))
        warnings.warn(ChoiceWarning(f"{path}: holds {len(groups)} series; showing the one {how}, {label(key)}. "
                                    "Others: " + "; ".join(label(k) for k in keys if k != key)
                                    + " (open one of their files, or pass series=...)", path, "series", key, keys,
                                    [label(k) for k in keys]), stacklevel=3)
    return groups[key]


def _pixels(s: _Slice) -> np.ndarray:
    """The file's frames (frames, rows, cols[, samples]) through the modality LUT."""
    import pydicom
    from pydicom.pixels import apply_modality_lut

    ds = pydicom.dcmread(s.path)
    try:
        arr = ds.pixel_array
    except (NotImplementedError, RuntimeError, ValueError, AttributeError) as exc:
        syntax = getattr(getattr(ds, "file_meta", None), "TransferSyntaxUID", None)
        name = getattr(syntax, "name", str(syntax))
        raise ReadError(s.path, f"its pixel data ({name}) could not be decoded: {exc}") from None
    samples = int(_number(ds.get("SamplesPerPixel"), 1))
    if s.frames == 1:
        arr = arr[None]
    if samples == 1 and ("RescaleSlope" in ds or "RescaleIntercept" in ds or "ModalityLUTSequence" in ds):
        arr = apply_modality_lut(arr, ds)
    if samples == 1 and "DoseGridScaling" in ds:  # RT dose: stored integers x scaling = Gy
        arr = arr * _number(ds.DoseGridScaling, 1.0)
    return arr.astype(np.float32) if arr.dtype == np.float64 else arr


def _frame_positions(s: _Slice) -> np.ndarray | None:
    """Per-frame ImagePositionPatient of an enhanced multi-frame file (None when it has none)."""
    import pydicom

    ds = pydicom.dcmread(s.path, stop_before_pixels=True)
    offsets = _floats(ds.get("GridFrameOffsetVector"), s.frames)
    if offsets is not None and s.position is not None and s.orientation is not None:  # RT dose grids
        normal = np.cross(s.orientation[:3], s.orientation[3:])
        return s.position + offsets[:, None] * normal
    try:
        groups = ds.PerFrameFunctionalGroupsSequence
        pos = [_floats(g.PlanePositionSequence[0].ImagePositionPatient, 3) for g in groups]
        shared = ds.SharedFunctionalGroupsSequence[0]
        if s.orientation is None:
            s.orientation = _floats(shared.PlaneOrientationSequence[0].ImageOrientationPatient, 6)
        if "PixelSpacing" not in ds:
            spacing = _floats(shared.PixelMeasuresSequence[0].PixelSpacing, 2)
            if spacing is not None and np.all(spacing > 0):
                s.spacing = (float(spacing[0]), float(spacing[1]))
    except (AttributeError, IndexError, KeyError, TypeError):
        return None
    return None if any(p is None for p in pos) or len(pos) != s.frames else np.asarray(pos)


def _stack_affine(path: Path, first: _Slice, positions: np.ndarray | None, n: int, warn: bool) -> np.ndarray:
    """Voxel (column, row, slice) -> LPS, from the first slice's orientation and the slices' positions."""
    row_dir, col_dir = (first.orientation[:3], first.orientation[3:]) if first.orientation is not None else \
        (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    normal = np.cross(row_dir, col_dir)
    if np.linalg.norm(normal) < 1e-6:
        raise ReadError(path, f"ImageOrientationPatient {np.concatenate([row_dir, col_dir]).tolist()} has parallel "
                              "row and column directions")
    affine = np.eye(4)
    affine[:3, 0] = row_dir / np.linalg.norm(row_dir) * first.spacing[1]   # along a row: the column spacing
    affine[:3, 1] = col_dir / np.linalg.norm(col_dir) * first.spacing[0]
    if positions is not None and n > 1:
        step = (positions[-1] - positions[0]) / (n - 1)
        gaps = np.diff(positions @ (normal / np.linalg.norm(normal)))
        if warn and np.ptp(gaps) > 0.01 * max(abs(float(np.mean(gaps))), 1e-9):
            warnings.warn(f"{path}: the slices are not evenly spaced (gaps {gaps.min():.4g} to {gaps.max():.4g} "
                          f"mm); they are shown at the mean gap {np.mean(gaps):.4g} mm", ReadWarning, stacklevel=4)
        affine[:3, 2] = step
    else:
        affine[:3, 2] = normal / np.linalg.norm(normal) * first.gap
    affine[:3, 3] = positions[0] if positions is not None else (first.position if first.position is not None
                                                                 else np.zeros(3))
    return affine


def _volume(path: Path, slices: list[_Slice], name: str, allow_nonfinite: bool, warn: bool = True) -> RegularVolume:
    """The slices (one position each, in stacking order) or one multi-frame file as a volume."""
    first = slices[0]
    if len(slices) == 1 and first.frames > 1:
        positions = _frame_positions(first)
        pixels = _pixels(first)
        n = first.frames
    else:
        positions = (np.asarray([s.position for s in slices])
                     if all(s.position is not None for s in slices) else None)
        pixels = np.concatenate([_pixels(s) for s in slices], axis=0)
        n = len(slices)
    if positions is not None and n > 1 and first.orientation is not None:
        normal = np.cross(first.orientation[:3], first.orientation[3:])
        order = np.argsort(positions @ normal, kind="stable")
        positions, pixels = positions[order], pixels[order]
        if np.any(np.diff(positions @ normal) <= 0):
            raise ReadError(path, "two slices of the series lie at the same position (a series of several "
                                  "volumes whose slices do not repeat evenly)")
    data = np.moveaxis(pixels, (0, 1, 2), (2, 1, 0))  # (frames, rows, cols[, s]) -> (cols, rows, frames[, s])
    return aligned_volume(path, data, lps_to_ras(_stack_affine(path, first, positions, n, warn)), name,
                          allow_nonfinite=allow_nonfinite, warn=warn)


def read_dicom(path: PathLike, series: str | None = None, allow_nonfinite: bool = True) -> RegularVolume | TimeSeries:
    """A DICOM series as a volume, or a time series when each position repeats (see the module)."""
    with _quiet():
        return _read(Path(os.fspath(path)), series, allow_nonfinite)


def _read(p: Path, series: str | None, allow_nonfinite: bool) -> RegularVolume | TimeSeries:
    if not p.exists():
        raise ReadError(p, "no such file or folder")
    if p.is_file() and not is_dicom(read_bytes(p, 132)) and p.suffix.lower() not in (".dcm", ".dicom", ".ima"):
        raise ReadError(p, "is not a DICOM file (no DICM marker at byte 128)")
    folder, files, chosen = _candidates(p)
    found, damaged = [], []
    for f in files:
        try:
            found.append(_header(f))
        except ReadError as exc:  # another file of a folder may be damaged; this one's reason if none reads
            damaged.append(exc)
    slices = _unique([s for s in found if s is not None], chosen)
    if not slices and damaged:
        raise damaged[0]
    if not slices:
        raise ReadError(p, "holds no DICOM image pydicom can read" if p.is_dir()
                        else "is not a DICOM image (no pixel data, or not a DICOM file pydicom can read)")
    picked = _pick_series(p, slices, chosen, series)
    def geometry(s: _Slice) -> tuple:
        return s.shape, None if s.orientation is None else tuple(np.round(s.orientation, 4))

    shapes = Counter(geometry(s) for s in picked)
    if len(shapes) > 1:
        mine = next((s for s in picked if s.path == chosen), None)
        common = geometry(mine) if mine is not None else shapes.most_common(1)[0][0]
        warnings.warn(f"{p}: the series mixes {len(shapes)} image sizes / orientations; showing the "
                      f"{shapes[common]} slice(s) of size {common[0][1]}x{common[0][0]}"
                      + (" of this file" if mine is not None else ""), ReadWarning, stacklevel=3)
        picked = [s for s in picked if geometry(s) == common]
    name = picked[0].quantity
    if any(s.position is None for s in picked):
        # without positions, only an opened folder is stacked (by InstanceNumber); an opened file shows alone
        picked = ([s for s in picked if s.path == chosen] if chosen is not None
                  else sorted(picked, key=lambda s: (s.instance, s.path.name)))
        return _volume(p, picked, name, allow_nonfinite)
    at: dict[tuple, list[_Slice]] = defaultdict(list)
    for s in picked:
        at[tuple(np.round(np.asarray(s.position), 3))].append(s)
    repeats = {len(v) for v in at.values()}
    if len(repeats) == 1 and (k := repeats.pop()) > 1 and len(at) > 1:
        for v in at.values():
            v.sort(key=lambda s: (s.time, s.instance, s.path.name))
        steps = [[v[t] for v in at.values()] for t in range(k)]
        times = np.asarray([np.mean([s.time for s in step]) for step in steps])
        if not np.all(np.diff(times) > 0):
            times = np.arange(k, dtype=np.float64)
        frames: list[Any] = [_volume(p, steps[0], name, allow_nonfinite)] + [None] * (k - 1)
        return TimeSeries(times, frames, loader=lambda t: _volume(p, steps[t], name, allow_nonfinite, warn=False),
                          source=str(p))
    if len(picked) != len(at):
        if chosen is None:
            raise ReadError(p, f"{len(picked)} slices at {len(at)} positions, repeating unevenly: open one of "
                               "its files, or pick a series (series=...)")
        warnings.warn(f"{p}: its series has {len(picked)} slices at {len(at)} positions, repeating unevenly; "
                      "showing this file's image alone", ReadWarning, stacklevel=2)
        picked = [s for s in picked if s.path == chosen]
    return _volume(p, picked, name, allow_nonfinite)
