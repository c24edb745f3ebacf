"""OME-Zarr images (NGFF 0.4 on Zarr v2, 0.5 on Zarr v3: bioimaging's cloud-ready format) and plain Zarr arrays,
through zarr-python. A Zarr store is a folder (``image.ome.zarr/``); it opens as one.

- Which level: the multiscale's finest level of at most ``MAX_VOXELS`` voxels per time step (a warning names the
  finer ones left out); ``level=0`` (or any index) picks one.
- Axes, by the multiscale's ``axes`` (names and types): space axes z, y, x become the volume's z, y, x; a ``channel``
  axis the components of one array; a ``time`` axis a time series. Voxel size and origin: the level's ``scale`` and
  ``translation`` (with the multiscale's own transformations applied after them), in the axes' unit.
- A plain Zarr array (no OME metadata) is read like an HDF5 array: (z, y, x), x fastest; a plain group shows its
  largest 3D / 4D array (or ``level=`` names one by its path).
- Safety: before zarr-python decodes anything, every array's codecs are checked against ``SAFE_CODECS`` on its JSON
  metadata: a Zarr v2 array may name any numcodecs codec, and numcodecs' ``pickle`` codec would unpickle the file's
  bytes. Object and structured dtypes are refused.
- Consistency (issue #32): an array's ``shape`` and ``chunks`` must be sizes of one length, and every chunk the store
  holds must lie inside the chunk grid they make (``check_stored_chunks``: a ``.zarray`` whose ``shape[0]`` was set
  from 6 to 1 read as one slice, the second chunk ignored); a multiscale's levels must have the shapes their scales
  give from level 0 (``check_levels``, within one voxel of the coarser level). Chunks missing inside the grid are
  valid Zarr (read as the fill value; writers skip empty chunks), so a shape made larger cannot be told from that.
"""
from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io.errors import ChoiceWarning, PathLike, ReadError
from volviz.model import RegularVolume, TimeSeries
from volviz.model.arrays import volume_of

MAX_VOXELS = 256 * 1024 * 1024
#: codecs that only decompress, reorder or check bytes (Zarr v3 names; numcodecs ids of Zarr v2 compressors/filters)
SAFE_CODECS = frozenset({"bytes", "transpose", "blosc", "zstd", "gzip", "zlib", "bz2", "lzma", "lz4", "crc32c",
                         "crc32", "adler32", "fletcher32", "sharding_indexed", "shuffle", "delta", "fixedscaleoffset",
                         "quantize", "bitround", "packbits", "numcodecs.blosc", "numcodecs.zstd", "numcodecs.zlib",
                         "numcodecs.gzip", "numcodecs.bz2", "numcodecs.lzma", "numcodecs.lz4", "numcodecs.shuffle",
                         "numcodecs.delta", "numcodecs.fixedscaleoffset", "numcodecs.quantize",
                         "numcodecs.bitround", "numcodecs.packbits", "numcodecs.crc32", "numcodecs.adler32",
                         "numcodecs.fletcher32"})


def _json(path: Path) -> dict[str, Any]:
    try:
        with open(path, "rb") as fh:
            text = fh.read(1 << 22)
        value = json.loads(text)
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise ReadError(path, f"is not readable Zarr metadata ({str(exc)[:200]})") from None
    if not isinstance(value, dict):
        raise ReadError(path, "is not a Zarr metadata object")
    return value


def _codec_names(meta: dict[str, Any]) -> list[str]:
    """Every codec a Zarr array's JSON metadata names (v2 compressor and filters, v3 codecs, nested ones too)."""
    names: list[str] = []
    for entry in [meta.get("compressor")] + list(meta.get("filters") or []) + list(meta.get("codecs") or []):
        if entry is None:
            continue
        if not isinstance(entry, dict):
            names.append(str(entry))
            continue
        names.append(str(entry.get("id", entry.get("name", ""))))
        inner = entry.get("configuration") or {}
        if isinstance(inner, dict):
            names += _codec_names({"codecs": inner.get("codecs") or [], "filters": inner.get("index_codecs") or []})
    return names


def check_array_metadata(folder: Path) -> None:
    """ReadError unless the array in ``folder`` uses only ``SAFE_CODECS`` and a numeric dtype."""
    meta_file = folder / ".zarray" if (folder / ".zarray").is_file() else folder / "zarr.json"
    meta = _json(meta_file)
    unsafe = sorted({n for n in _codec_names(meta) if n.lower() not in SAFE_CODECS})
    if unsafe:
        raise ReadError(folder, f"its Zarr array uses the codec(s) {', '.join(unsafe)}, which volviz does not run "
                                "(only decompression and byte-order codecs; never one that unpickles or runs code)")
    dtype = meta.get("dtype", meta.get("data_type"))
    text = json.dumps(dtype)
    if isinstance(dtype, list) or "O" in text or "object" in text.lower() or "string" in text.lower():
        raise ReadError(folder, f"its Zarr array holds {text} values; volviz reads numbers")


def _sizes(value: Any, least: int) -> bool:
    return isinstance(value, list) and all(type(n) is int and n >= least for n in value)


def _mapping(value: Any) -> dict[str, Any]:
    return value if isinstance(value, dict) else {}


def _grid(meta: dict[str, Any]) -> tuple[Any, Any, str, str]:
    """(shape, chunk shape, chunk key prefix, separator) of a Zarr v2 ``.zarray`` or v3 ``zarr.json``."""
    if "chunks" in meta or meta.get("zarr_format") == 2:
        return meta.get("shape"), meta.get("chunks"), "", str(meta.get("dimension_separator") or ".")
    chunks = _mapping(_mapping(meta.get("chunk_grid")).get("configuration")).get("chunk_shape")
    encoding = _mapping(meta.get("chunk_key_encoding"))
    separator = _mapping(encoding.get("configuration")).get("separator")
    if encoding.get("name") == "v2":
        return meta.get("shape"), chunks, "", str(separator or ".")
    return meta.get("shape"), chunks, "c", str(separator or "/")


def check_stored_chunks(folder: Path) -> None:
    """ReadError unless the array's ``shape`` and ``chunks`` are sizes of one length and every chunk stored in
    ``folder`` lies inside the grid of ``ceil(shape / chunks)`` chunks they make: a stored chunk outside it means the
    shape was made smaller than the data written (zarr-python deletes such chunks when it shrinks an array)."""
    meta_file = folder / ".zarray" if (folder / ".zarray").is_file() else folder / "zarr.json"
    shape, chunks, prefix, sep = _grid(_json(meta_file))
    if not _sizes(shape, 0):
        raise ReadError(meta_file, f"its shape {json.dumps(shape)[:80]} is not a list of sizes (whole numbers >= 0)")
    if not _sizes(chunks, 1) or len(chunks) != len(shape):
        raise ReadError(meta_file, f"its chunk shape {json.dumps(chunks)[:80]} is not {len(shape)} sizes >= 1 "
                                   f"(one per axis of the shape {shape})")
    if not shape:
        return
    grid = [-(-n // c) for n, c in zip(shape, chunks)]
    start = folder / prefix if prefix else folder
    for key in _chunk_keys(start, sep):
        if len(key) != len(grid) or any(i >= n for i, n in zip(key, grid)):
            name = (prefix + sep if prefix else "") + sep.join(map(str, key))
            raise ReadError(meta_file, f"its shape {shape} (chunks {chunks}: a grid of {' x '.join(map(str, grid))} "
                                       f"chunks) disagrees with its stored chunk {name}, which lies outside it: the "
                                       "shape or the chunk shape is damaged")


def _chunk_keys(start: Path, sep: str) -> list[tuple[int, ...]]:
    """The chunk indices of the files under ``start`` named as chunk keys (numbers joined by ``sep``; with ``/``,
    nested folders); other files (metadata, a stray ``.DS_Store``) are not chunks."""
    import os

    keys = []
    if sep == "/":
        for here, _, files in os.walk(start):
            parts = Path(here).relative_to(start).parts
            if all(part.isdigit() for part in parts):
                keys += [tuple(int(v) for v in (*parts, f)) for f in files if f.isdigit()]
        return keys
    if start.is_dir():
        for entry in os.scandir(start):
            words = entry.name.split(sep)
            if entry.is_file() and all(w.isdigit() for w in words):
                keys.append(tuple(int(w) for w in words))
    return keys


def check_levels(root: Path, datasets: list[dict[str, Any]], arrays: list[Any]) -> None:
    """ReadError unless each level's shape is what its scale gives from level 0's (``n0 * scale0 / scale``, within
    one voxel: a writer may round a halved size either way) on every axis."""
    if len(arrays) < 2:
        return
    n = len(arrays[0].shape)
    first = np.asarray(arrays[0].shape, dtype=np.float64)
    scale0, _ = _transform(datasets[0].get("coordinateTransformations"), n)
    for dataset, array in zip(datasets[1:], arrays[1:]):
        scale, _ = _transform(dataset.get("coordinateTransformations"), n)
        if len(array.shape) != n or not (np.all(np.isfinite(scale)) and np.all(scale > 0)
                                         and np.all(np.isfinite(scale0)) and np.all(scale0 > 0)):
            continue
        expected = first * scale0 / scale
        if np.any(np.abs(np.asarray(array.shape) - expected) > 1 + 1e-9):
            raise ReadError(root / str(dataset["path"]), f"its shape {list(array.shape)} disagrees with level 0's "
                            f"{list(arrays[0].shape)} at the scales {scale.tolist()} and {scale0.tolist()} "
                            f"(expected about {[round(float(v), 2) for v in expected]}): a shape or a scale is damaged")


def _arrays(root: Path) -> list[Path]:
    """Every array folder under ``root`` (itself included), by its metadata file."""
    found = []
    for meta in list(root.rglob(".zarray")) + list(root.rglob("zarr.json")):
        if meta.name == "zarr.json" and _json(meta).get("node_type") != "array":
            continue
        found.append(meta.parent)
    return sorted(set(found))


def _multiscale(root: Path) -> dict[str, Any] | None:
    attrs: dict[str, Any] = {}
    if (root / ".zattrs").is_file():
        attrs = _json(root / ".zattrs")
    elif (root / "zarr.json").is_file():
        attrs = _json(root / "zarr.json").get("attributes") or {}
    attrs = attrs.get("ome", attrs)
    scales = attrs.get("multiscales")
    return scales[0] if isinstance(scales, list) and scales and isinstance(scales[0], dict) else None


def _transform(transforms: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
    scale, shift = np.ones(n), np.zeros(n)
    for t in transforms or []:
        if not isinstance(t, dict):
            continue
        if t.get("type") == "scale" and len(t.get("scale", [])) == n:
            factor = np.asarray(t["scale"], dtype=np.float64)
            scale, shift = scale * factor, shift * factor
        elif t.get("type") == "translation" and len(t.get("translation", [])) == n:
            shift = shift + np.asarray(t["translation"], dtype=np.float64)
    return scale, shift


def _open(folder: Path) -> Any:
    import zarr

    check_array_metadata(folder)
    check_stored_chunks(folder)
    try:
        return zarr.open_array(str(folder), mode="r")
    except Exception as exc:  # zarr-python raises many kinds on damaged metadata
        raise ReadError(folder, f"zarr-python could not open the array ({type(exc).__name__}: "
                                f"{str(exc)[:200]})") from None


def _voxels(array: Any) -> int:
    return int(np.prod(array.shape, dtype=object))


def read_zarr(path: PathLike, level: int | str | None = None,
              allow_nonfinite: bool = True) -> RegularVolume | TimeSeries:
    """An OME-Zarr image or a Zarr array as a volume or a time series (see the module)."""
    root = Path(path)
    if not root.is_dir():
        raise ReadError(root, "is not a Zarr store (a folder)")
    multiscale = _multiscale(root)
    if multiscale is None:
        return _plain(root, level, allow_nonfinite)
    datasets = [d for d in multiscale.get("datasets") or [] if isinstance(d, dict) and "path" in d]
    axes = [a if isinstance(a, dict) else {"name": str(a)} for a in multiscale.get("axes") or []]
    if not datasets:
        raise ReadError(root, "its OME multiscales metadata lists no datasets")
    arrays = [_open(root / str(d["path"])) for d in datasets]
    check_levels(root, datasets, arrays)
    if level is not None:
        if not (isinstance(level, int) and 0 <= level < len(arrays)):
            raise ReadError(root, f"level {level!r} is not one of its {len(arrays)} levels (0 = finest)")
        index = level
    else:
        names = [str(a.get("name", "")).lower() for a in axes]
        per_step = [_voxels(a) // max(a.shape[names.index("t")] if "t" in names else 1, 1) for a in arrays]
        index = next((i for i, v in enumerate(per_step) if v <= MAX_VOXELS), len(arrays) - 1)
    if len(arrays) > 1:
        shapes = ["x".join(map(str, a.shape)) for a in arrays]
        said = (f"showing level {index} ({shapes[index]}); the finer levels hold more than {MAX_VOXELS} voxels per "
                "step (level=0 reads the finest)" if level is None and index > 0
                else f"showing level {index} ({shapes[index]}) of {len(arrays)} (level=N picks another)")
        warnings.warn(ChoiceWarning(f"{root}: {said}", root, "level", index, list(range(len(arrays))),
                                    [f"level {i} ({shape})" + (" — finest" if i == 0 else "")
                                     for i, shape in enumerate(shapes)]), stacklevel=2)
    array = arrays[index]
    n = len(array.shape)
    if len(axes) != n:
        axes = [{"name": name} for name in "tczyx"[-n:]]
    scale, shift = _transform(datasets[index].get("coordinateTransformations"), n)
    outer_scale, outer_shift = _transform(multiscale.get("coordinateTransformations"), n)
    scale, shift = scale * outer_scale, shift * outer_scale + outer_shift
    return _assemble(root, array, [str(a.get("name", "")).lower() for a in axes], scale, shift, allow_nonfinite)


def _plain(root: Path, level: int | str | None, allow_nonfinite: bool) -> RegularVolume | TimeSeries:
    folders = _arrays(root)
    if isinstance(level, str):
        folders = [f for f in folders if f.relative_to(root).as_posix() == level.strip("/")]
    arrays = [(f, _open(f)) for f in folders]
    arrays = [(f, a) for f, a in arrays if len(a.shape) in (3, 4) and a.dtype.kind in "biuf"]
    if not arrays:
        raise ReadError(root, "holds no numeric 3D or 4D Zarr array" + (f" named {level!r}" if level else ""))
    folder, array = max(arrays, key=lambda item: _voxels(item[1]))
    n = len(array.shape)
    names = list("zyx") if n == 3 else (list("zyxc") if array.shape[3] <= 4 else list("tzyx"))
    return _assemble(root, array, names, np.ones(n), np.zeros(n), allow_nonfinite)


def _assemble(root: Path, array: Any, names: list[str], scale: np.ndarray, shift: np.ndarray,
              allow_nonfinite: bool) -> RegularVolume | TimeSeries:
    """The array with its named axes as a (time series of) volume(s) (x, y, z[, c])."""
    from volviz.io._checks import check_finite

    space = [names.index(a) for a in "zyx" if a in names]
    if len(space) < 2:
        raise ReadError(root, f"its axes {', '.join(names)} hold fewer than two of z, y, x")
    channel = names.index("c") if "c" in names else None
    time = names.index("t") if "t" in names else None
    extra = [i for i in range(len(names)) if i not in space + [channel, time] and array.shape[i] > 1]
    if extra:
        raise ReadError(root, f"its axes {', '.join(names)}: volviz reads space, one channel and one time axis")
    sx, sy, sz = (float(scale[names.index(a)]) if a in names else 1.0 for a in "xyz")
    ox, oy, oz = (float(shift[names.index(a)]) if a in names else 0.0 for a in "xyz")
    sx, sy, sz = (abs(v) if np.isfinite(v) and v != 0 else 1.0 for v in (sx, sy, sz))
    name = root.name.split(".")[0] or "intensity"

    def step(t: int | None) -> RegularVolume:
        index: list[Any] = [slice(None)] * len(names)
        if time is not None:
            index[time] = t or 0
        for i in range(len(names)):
            if i not in space and i != channel and i != time:
                index[i] = 0
        try:
            block = np.asarray(array[tuple(index)])
        except Exception as exc:  # a damaged chunk: zarr-python and numcodecs raise many kinds
            raise ReadError(root, f"a chunk could not be read ({type(exc).__name__}: {str(exc)[:200]})") from None
        kept = [i for i in range(len(names)) if not isinstance(index[i], int)]
        order = [kept.index(i) for i in sorted(space, key=lambda i: "xyz".index(names[i]))]
        order += [kept.index(channel)] if channel is not None else []
        data = np.transpose(block, order)
        while data.ndim < 3 + (channel is not None):
            data = np.expand_dims(data, 2)
        if data.dtype.kind not in "biuf":
            raise ReadError(root, f"its array holds {data.dtype} values; volviz reads numbers")
        check_finite(root, data, allow_nonfinite)
        return volume_of(np.ascontiguousarray(data), name, (sx, sy, sz), (ox, oy, oz), source=str(root))

    if time is None or array.shape[time] == 1:
        return step(None)
    count = int(array.shape[time])
    frames: list[Any] = [step(0)] + [None] * (count - 1)
    interval = float(scale[time]) if np.isfinite(scale[time]) and scale[time] > 0 else 1.0
    return TimeSeries(np.arange(count) * interval, frames, loader=step, source=str(root))
