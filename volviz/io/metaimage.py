"""MetaImage (ITK/VTK): a text header ``Key = Value`` per line, ending with ``ElementDataFile``; data in a
separate file (.mhd + .raw), after the header (``ElementDataFile = LOCAL``, .mha), or in one file per slice
(``ElementDataFile = LIST`` followed by their names, or a pattern ``quarter.%d 1 93 1``). Optional zlib compression
(``CompressedData = True``). 2D images become Image2D (rows = DimSize[1]), 3D images RegularVolume.
"""
from __future__ import annotations

import warnings
import zlib
from pathlib import Path

import numpy as np

from volviz.io._checks import (
    check_dims, check_finite, describe_bytes, describe_dims, file_size, parse_float, parse_int, read_at, read_bytes,
    require_bytes,
)
from volviz.io.errors import PathLike, ReadError, ReadWarning, bytes_and_size, human_bytes
from volviz.io.raw import read_slice_stack
from volviz.io.trailing import check_trailing
from volviz.model import Image2D, RegularVolume, vec3

ELEMENT_TYPES = {
    "MET_CHAR": "i1", "MET_UCHAR": "u1", "MET_SHORT": "i2", "MET_USHORT": "u2", "MET_INT": "i4", "MET_UINT": "u4",
    "MET_LONG": "i4", "MET_ULONG": "u4", "MET_LONG_LONG": "i8", "MET_ULONG_LONG": "u8", "MET_FLOAT": "f4",
    "MET_DOUBLE": "f8",
}
_HEADER_LIMIT = 65536
DEFLATE_MAX_RATIO = 1032  # zlib's deflate cannot expand data by more than about 1032:1
_TRUE = {"true", "1", "yes"}


def parse_mhd_header(path: PathLike, head: bytes) -> tuple[dict[str, str], int]:
    """``({key: value}, offset after the ElementDataFile line)``; keys are case-normalised to MetaIO spelling."""
    fields: dict[str, str] = {}
    pos = 0
    while True:
        end = head.find(b"\n", pos)
        if end < 0:
            if pos < len(head) and b"ElementDataFile".lower() in head[pos:].lower():
                end = len(head)
            else:
                raise ReadError(path, "MetaImage header has no ElementDataFile line (or it is longer than "
                                      f"{_HEADER_LIMIT} bytes)")
        line = head[pos:end].strip()
        pos = end + 1
        if not line or line.startswith(b"#"):
            continue
        key, sep, value = line.partition(b"=")
        if not sep:
            raise ReadError(path, f"MetaImage header line {_line_number(head, pos)} is not 'Key = Value' (it is "
                                  f"{describe_bytes(line)})")
        try:
            k = key.strip().decode("ascii")
            v = value.strip().decode("utf-8")
        except UnicodeDecodeError:
            raise ReadError(path, f"MetaImage header line {_line_number(head, pos)} is not text") from None
        fields[k.lower()] = v
        if k.lower() == "elementdatafile":
            return fields, min(pos, len(head))


def _line_number(head: bytes, end: int) -> str:
    """``"3"``: the 1-based number of the header line that ends just before offset ``end``."""
    return str(head.count(b"\n", 0, max(end - 1, 0)) + 1)


def _floats(path: PathLike, fields: dict[str, str], keys: tuple[str, ...], n: int, default: float,
            positive: bool = False) -> tuple[float, ...]:
    for key in keys:
        if key in fields:
            tokens = fields[key].split()
            if len(tokens) < n:
                raise ReadError(path, f"MetaImage {key} has {len(tokens)} values, NDims is {n}")
            return tuple(parse_float(path, t, f"MetaImage {key}", positive) for t in tokens[:n])
    return (default,) * n


def _slice_files(path: PathLike, data_name: str, rest: bytes, nz: int) -> list[Path]:
    """The slice files of ``ElementDataFile = LIST`` (one name per line after it) or of a printf pattern
    ``name.%03d first last step``, relative to the header's folder; as many as there are slices."""
    folder = Path(path).parent
    if data_name.upper().startswith("LIST"):
        names = [ln.strip() for ln in rest.decode("utf-8", "replace").splitlines() if ln.strip()][:nz]
    else:
        parts = data_name.split()
        if len(parts) != 4:
            raise ReadError(path, "MetaImage ElementDataFile pattern is not 'name%d first last step'")
        first, last, step = (parse_int(path, t, "MetaImage ElementDataFile pattern") for t in parts[1:])
        if step == 0 or (last - first) // step + 1 != nz:
            raise ReadError(path, f"MetaImage ElementDataFile pattern names "
                                  f"{max((last - first) // step + 1, 0) if step else 0} slices, DimSize {nz}")
        try:
            names = [parts[0] % i for i in range(first, last + (1 if step > 0 else -1), step)]
        except (TypeError, ValueError):
            raise ReadError(path, "MetaImage ElementDataFile pattern's file name is not a printf pattern") from None
    if len(names) != nz:
        raise ReadError(path, f"MetaImage ElementDataFile LIST names {len(names)} slice files, DimSize {nz}")
    return [folder / name for name in names]


def _inflate(data_path: Path, offset: int, stored: int, n_bytes: int, declared: int | None, what: str) -> bytes:
    """The ``n_bytes`` a zlib stream at ``offset`` (running to the end of the file, ``stored`` bytes) inflates to.

    The inflated size is what must agree with the dimensions: a ``CompressedDataSize`` (``declared``) that differs
    from the stream's length is stale (tools rewrite the data and keep the header), and is a ReadWarning when the
    stream inflates in full; it names the cause (a file shorter than it says) when the stream falls short."""
    if stored <= 0:
        raise ReadError(data_path, "MetaImage compressed data is empty")
    if n_bytes > DEFLATE_MAX_RATIO * stored + 64:
        raise ReadError(data_path, f"{what} needs {bytes_and_size(n_bytes)}, more than its "
                                   f"{stored} compressed bytes can inflate to (zlib expands at most "
                                   f"{DEFLATE_MAX_RATIO}:1)")
    packed = bytes(read_at(data_path, offset, stored))
    try:
        inflater = zlib.decompressobj()
        raw = inflater.decompress(packed, n_bytes + 1)
    except zlib.error as exc:
        raise ReadError(data_path, f"MetaImage zlib data is corrupt ({exc})") from None
    if len(raw) != n_bytes:
        if declared is not None:
            require_bytes(data_path, declared, stored, "MetaImage CompressedDataSize")
        raise ReadError(data_path, f"{what} inflates to {len(raw)}{'+' if len(raw) > n_bytes else ''} bytes, "
                                   f"the header needs {n_bytes} ({human_bytes(n_bytes)})")
    used = stored - len(inflater.unused_data) - len(inflater.unconsumed_tail)
    if declared is not None and declared != used:
        warnings.warn(ReadWarning(f"{data_path}: the header's CompressedDataSize ({declared}) is not the length of "
                                  f"its zlib stream ({used} bytes), which inflates to exactly the {n_bytes} bytes "
                                  "the dimensions need: the stream is read, the stale size ignored"), stacklevel=4)
    return raw


def read_metaimage(path: PathLike, allow_nonfinite: bool = True) -> RegularVolume | Image2D:
    """Read .mhd (+ data file) or .mha into RegularVolume (3D) or Image2D (2D, any number of channels).

    Problems with a separate data file are reported against the header, naming the data file too."""
    try:
        return _read_metaimage(path, allow_nonfinite)
    except ReadError as exc:
        if exc.path != str(path):
            raise ReadError(path, f"data file {exc.path}: {exc.problem}") from None
        raise


def _read_metaimage(path: PathLike, allow_nonfinite: bool) -> RegularVolume | Image2D:
    size = file_size(path)
    head = read_bytes(path, _HEADER_LIMIT)
    fields, header_end = parse_mhd_header(path, head)
    ndims = parse_int(path, fields.get("ndims", "3"), "MetaImage NDims")
    if ndims not in (2, 3):
        raise ReadError(path, f"MetaImage NDims = {ndims}; only 2D and 3D images are supported")
    if "dimsize" not in fields:
        raise ReadError(path, "MetaImage header has no DimSize")
    dim_tokens = fields["dimsize"].split()
    if len(dim_tokens) != ndims:
        raise ReadError(path, f"MetaImage DimSize has {len(dim_tokens)} values, not NDims = {ndims}")
    dims = check_dims(path, [parse_int(path, t, "MetaImage DimSize") for t in dim_tokens], "MetaImage DimSize")
    etype = fields.get("elementtype", "").upper()
    if etype not in ELEMENT_TYPES:
        raise ReadError(path, f"MetaImage ElementType is {'missing' if not etype else 'not one of'} the supported "
                              f"types ({', '.join(ELEMENT_TYPES)})")
    channels = parse_int(path, fields.get("elementnumberofchannels", "1"), "MetaImage ElementNumberOfChannels")
    if channels < 1 or (ndims == 3 and channels != 1):
        raise ReadError(path, f"MetaImage with {channels} channels per voxel is not supported in {ndims}D")
    spacing = _floats(path, fields, ("elementspacing", "elementsize"), ndims, 1.0, positive=True)
    origin = _floats(path, fields, ("offset", "origin", "position"), ndims, 0.0)
    if "transformmatrix" in fields:
        matrix = _floats(path, fields, ("transformmatrix",), ndims * ndims, 0.0)
        if not np.allclose(np.reshape(matrix, (ndims, ndims)), np.eye(ndims)):
            warnings.warn(f"{path}: MetaImage TransformMatrix {matrix} is not the identity; the orientation is "
                          "ignored (volviz volumes are axis-aligned)", UserWarning, stacklevel=2)
    msb = fields.get("elementbyteordermsb", fields.get("binarydatabyteordermsb", "false")).lower() in _TRUE
    disk = np.dtype(ELEMENT_TYPES[etype]).newbyteorder(">" if msb else "<")
    binary = fields.get("binarydata", "true").lower() in _TRUE
    compressed = fields.get("compresseddata", "false").lower() in _TRUE
    n_values = int(np.prod(dims, dtype=object)) * channels
    n_bytes = n_values * disk.itemsize

    data_name = fields["elementdatafile"]
    if data_name.upper() == "LOCAL":
        data_path, data_size, offset = Path(path), size, header_end
    elif data_name.upper().startswith("LIST") or "%" in data_name:
        if ndims != 3 or compressed or not binary:
            raise ReadError(path, "MetaImage slice files (ElementDataFile LIST or a pattern) are read for 3D "
                                  "uncompressed binary data only")

        slices = _slice_files(path, data_name, head[header_end:], dims[2])
        header_size = parse_int(path, fields.get("headersize", "0"), "MetaImage HeaderSize")
        return read_slice_stack(slices, dims, disk.newbyteorder("="), "big" if msb else "little",
                                max(header_size, 0), spacing, origin, allow_nonfinite, name="MetaImage")
    else:
        data_path = Path(path).parent / data_name
        if not data_path.exists():
            raise ReadError(path, f"MetaImage data file {data_name!r} not found next to the header "
                                  f"(looked for {data_path})")
        data_size, offset = file_size(data_path), 0
    header_size = parse_int(path, fields.get("headersize", "0"), "MetaImage HeaderSize")
    what = f"MetaImage {describe_dims(dims)} {etype} {'compressed ' if compressed else ''}data"
    if not binary:
        if compressed:
            raise ReadError(path, "MetaImage with BinaryData = False and CompressedData = True is not valid")
        require_bytes(data_path, 2 * n_values - 1, data_size - offset, what + " as text")
        tokens = read_bytes(data_path)[offset:].split()
        if len(tokens) < n_values:
            raise ReadError(data_path, f"{what} as text holds {len(tokens)} values, the header needs {n_values}")
        try:
            values = np.array([float(t) for t in tokens[:n_values]]).astype(disk.newbyteorder("="))
        except ValueError:
            raise ReadError(data_path, "MetaImage text data holds a value that is not a number") from None
    elif compressed:
        declared = (parse_int(path, fields["compresseddatasize"], "MetaImage CompressedDataSize")
                    if "compresseddatasize" in fields else None)
        values = np.frombuffer(_inflate(data_path, offset, data_size - offset, n_bytes, declared, what),
                               dtype=disk).astype(disk.newbyteorder("="))
    else:
        if header_size == -1:
            offset = data_size - n_bytes
            require_bytes(data_path, n_bytes, data_size, what)
        elif header_size < -1:
            raise ReadError(path, f"MetaImage HeaderSize {header_size} is invalid")
        else:
            offset += header_size
            require_bytes(data_path, n_bytes, data_size - offset, what)
            # a DimSize that claims fewer slices than the file holds would reinterpret the voxels (issue #32)
            check_trailing(data_path, f"DimSize {' '.join(map(str, dims))} of {etype}", n_bytes,
                           data_size - offset - n_bytes, n_bytes // dims[-1])
        values = np.frombuffer(read_at(data_path, offset, n_bytes), dtype=disk)
        if not disk.isnative:
            values = values.astype(disk.newbyteorder("="))
    check_finite(data_path, values, allow_nonfinite)
    if ndims == 2:
        shape = (dims[1], dims[0]) + ((channels,) if channels > 1 else ())
        return Image2D(values.reshape(shape), spacing=(spacing[0], spacing[1]), origin=(origin[0], origin[1]),
                       source=str(path))
    return RegularVolume(values.reshape(dims, order="F"), spacing=vec3(spacing, "spacing"),
                         origin=vec3(origin, "origin"), name="MetaImage",
                         source=str(path))
