"""VisIt's Brick of Values (``.bov``): a short ``KEY: value`` text header naming a raw data file, the format many HPC
codes write for VisIt (and ParaView reads through its VisIt plugins).

Keys read: ``DATA_FILE`` (relative to the header), ``DATA_SIZE`` (nx ny nz, x fastest), ``DATA_FORMAT`` (BYTE,
SHORT, INT, FLOAT, DOUBLE, and the unsigned / 64-bit spellings), ``DATA_ENDIAN``, ``DATA_COMPONENTS``,
``BYTE_OFFSET``, ``VARIABLE`` (the array's name), ``CENTERING`` (``zonal``: one value per cell of the brick, placed at
the cell centres; ``nodal``: at the brick's grid points), ``BRICK_ORIGIN`` and ``BRICK_SIZE`` (the brick's corner and
extent), ``TIME``. The data file must hold exactly what the header says (``volviz.io.raw``'s size check).
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from volviz.io._checks import check_dims, check_file, describe_bytes, parse_float, parse_int, read_at, read_bytes
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.io.raw import _size_problem, decode_samples, file_dtype, swapped_looks_right
from volviz.model import RegularVolume
from volviz.model.arrays import volume_of

FORMATS = {"BYTE": "u1", "CHAR": "u1", "SHORT": "i2", "UNSIGNED_SHORT": "u2", "INT": "i4", "UNSIGNED_INT": "u4",
           "LONG": "i8", "FLOAT": "f4", "DOUBLE": "f8"}
MAX_HEADER_BYTES = 65536


def is_bov(head: bytes) -> bool:
    return b"DATA_FILE" in head[:4096] and b"DATA_SIZE" in head[:4096]


def parse_bov_header(path: PathLike, text: bytes) -> dict[str, str]:
    """``{KEY: value}`` of a BOV header (comments after ``#`` and blank lines skipped, keys upper-cased)."""
    fields: dict[str, str] = {}
    for number, line in enumerate(text.decode("utf-8", "replace").splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        key, colon, value = line.partition(":")
        if not colon:
            raise ReadError(path, f"BOV header line {number} is not 'KEY: value'")
        fields[key.strip().upper()] = value.strip()
    return fields


#: the keys a header may leave out, and what is read then
DEFAULTS = {"DATA_ENDIAN": "LITTLE", "CENTERING": "zonal", "BRICK_ORIGIN": "0 0 0", "BRICK_SIZE": "DATA_SIZE",
            "DATA_COMPONENTS": "1", "BYTE_OFFSET": "0"}


def _warn_if_cut(path: PathLike, head: bytes, fields: dict[str, str]) -> None:
    """A header whose last line has no line end may have been cut short, and the keys after the cut read with
    their defaults (a cut that drops ``DATA_ENDIAN: BIG`` reads every sample byte-swapped): a ReadWarning naming
    the line and the defaults used (issue #32). A header that ends with its line end, or that sets every key,
    says nothing."""
    missing = [f"{k} {v}" for k, v in DEFAULTS.items() if k not in fields]
    if head.endswith(b"\n") or not missing:
        return
    last = head.decode("utf-8", "replace").splitlines()[-1][:60]
    warnings.warn(f"{path}: its header's last line ({last!r}) has no line end: if the header was cut short, keys "
                  f"are missing and read with their defaults ({', '.join(missing)})", ReadWarning, stacklevel=3)


def _warn_if_swapped(path: PathLike, raw: bytes | bytearray, disk: np.dtype) -> None:
    """A header that does not state ``DATA_ENDIAN`` is read little-endian (BOV's default); when the samples look
    byte-swapped so (``raw.swapped_looks_right``), a ReadWarning says why (a header that lost its
    ``DATA_ENDIAN: BIG`` line reads every sample byte-swapped; issue #32)."""
    why = swapped_looks_right(raw, disk)
    if why is not None:
        warnings.warn(f"{path}: its header does not state DATA_ENDIAN, so its samples are read little-endian (BOV's "
                      f"default), but they look byte-swapped: {why}; if the header lost a 'DATA_ENDIAN: BIG' line, "
                      "add it", ReadWarning, stacklevel=3)


def _floats(path: PathLike, fields: dict[str, str], key: str, default: tuple[float, ...]) -> tuple[float, ...]:
    if key not in fields:
        return default
    values = fields[key].split()
    if len(values) != 3:
        raise ReadError(path, f"BOV {key} has {len(values)} values, needs 3")
    return tuple(parse_float(path, v, f"BOV {key}") for v in values)


def read_bov(path: PathLike, allow_nonfinite: bool = True) -> RegularVolume:
    """A BOV header and its data file as a volume (see the module)."""
    p = check_file(path)
    head = read_bytes(p, MAX_HEADER_BYTES + 1)
    if len(head) > MAX_HEADER_BYTES or not is_bov(head):
        raise ReadError(p, f"is not a BOV header (no DATA_FILE and DATA_SIZE lines; its content is "
                           f"{describe_bytes(head[:4096])})")
    fields = parse_bov_header(p, head)
    _warn_if_cut(p, head, fields)
    for key in ("DATA_FILE", "DATA_SIZE", "DATA_FORMAT"):
        if not fields.get(key):
            raise ReadError(p, f"BOV header has no {key}")
    sizes = fields["DATA_SIZE"].split()
    if len(sizes) != 3:
        raise ReadError(p, f"BOV DATA_SIZE has {len(sizes)} values, needs 3")
    dims = check_dims(p, [parse_int(p, v, "BOV DATA_SIZE") for v in sizes], "BOV DATA_SIZE")
    kind = fields["DATA_FORMAT"].upper()
    if kind not in FORMATS:
        raise ReadError(p, f"BOV DATA_FORMAT is not one of {', '.join(FORMATS)}")
    components = parse_int(p, fields.get("DATA_COMPONENTS", "1"), "BOV DATA_COMPONENTS")
    offset = parse_int(p, fields.get("BYTE_OFFSET", "0"), "BOV BYTE_OFFSET")
    if components < 1 or offset < 0:
        raise ReadError(p, f"BOV DATA_COMPONENTS {components} / BYTE_OFFSET {offset} out of range")
    endian = fields.get("DATA_ENDIAN", "LITTLE").upper()
    if endian not in ("LITTLE", "BIG"):
        raise ReadError(p, "BOV DATA_ENDIAN is neither LITTLE nor BIG")
    disk = file_dtype(FORMATS[kind], endian.lower())
    data_path = Path(fields["DATA_FILE"])
    data_path = data_path if data_path.is_absolute() else p.parent / data_path
    if not data_path.is_file():
        raise ReadError(p, f"its data file {fields['DATA_FILE']} is missing (looked for {data_path})")
    _size_problem(data_path, (components, *dims), disk, offset, data_path.stat().st_size)
    n = components * int(np.prod(dims))
    raw = read_at(data_path, offset, n * disk.itemsize)
    if "DATA_ENDIAN" not in fields:
        _warn_if_swapped(p, raw, disk)
    values = decode_samples(data_path, raw, disk, allow_nonfinite)
    data = values.reshape((components, *dims), order="F")
    data = data[0] if components == 1 else np.moveaxis(data, 0, -1)
    nodal = fields.get("CENTERING", "zonal").lower().startswith("nod")
    origin = np.asarray(_floats(p, fields, "BRICK_ORIGIN", (0.0, 0.0, 0.0)))
    size = np.asarray(_floats(p, fields, "BRICK_SIZE", tuple(float(d) for d in dims)))
    spacing = size / np.maximum(np.asarray(dims) - (1 if nodal else 0), 1)
    if np.any(spacing <= 0):
        raise ReadError(p, f"BOV BRICK_SIZE {tuple(size)} is not positive")
    if not nodal:
        origin = origin + spacing / 2.0                      # zonal values sit at the cell centres
    name = fields.get("VARIABLE", "").strip() or "values"
    sx, sy, sz = (float(v) for v in spacing)
    ox, oy, oz = (float(v) for v in origin)
    return volume_of(np.ascontiguousarray(data), name, (sx, sy, sz), (ox, oy, oz), source=str(p))
