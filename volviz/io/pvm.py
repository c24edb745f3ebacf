"""PVM volumes, the libMini volume format (versions 1, 2 and 3; 8- and 16-bit voxels).

Layout (libMini ``ddsbase.cpp``, summarised in shared/data/README.md):

- ``PVM\\nX Y Z\\nB\\n`` + data                 (version 1, unit spacing)
- ``PVM2\\nX Y Z\\nsx sy sz\\nB\\n`` + data     (version 2)
- ``PVM3\\nX Y Z\\nsx sy sz\\nB\\n`` + data + optional NUL-terminated description, courtesy, parameter and comment
  strings (version 3)

``B`` is bytes per voxel: 1 (uint8) or 2 (uint16, big-endian, i.e. most significant byte first). Voxels are stored
with x fastest. Files wrapped in libMini's DDS compression start with ``DDS v3d`` or ``DDS v3e``; they are recognised
and refused with a ReadError (DDS decoding is not implemented).
"""
from __future__ import annotations

import numpy as np

from volviz.io._checks import (
    check_dims, describe_bytes, describe_dims, file_size, parse_float, parse_int, read_at, read_bytes, require_bytes,
)
from volviz.io.errors import PathLike, ReadError
from volviz.model import RegularVolume

DDS_MAGICS = (b"DDS v3d", b"DDS v3e")
_HEADER_LIMIT = 1024  # a PVM header is a few short text lines


def is_pvm(head: bytes) -> bool:
    return head.startswith((b"PVM\n", b"PVM2\n", b"PVM3\n")) or head.startswith(DDS_MAGICS)


def parse_pvm_header(path: PathLike,
                     head: bytes) -> tuple[int, tuple[int, int, int], tuple[float, float, float], int, int]:
    """Parse the text header: ``(version, dims, spacing, bytes_per_voxel, data_offset)``; ReadError if malformed."""
    if head.startswith(DDS_MAGICS):
        raise ReadError(path, f"is a DDS-compressed PVM file (DDS v3{chr(head[6])}); libMini DDS decompression is "
                              "not supported - decompress it first (e.g. libMini's pvm2raw/pvm2pvm tools)")
    if head.startswith(b"PVM\n"):
        version, n_lines = 1, 2
    elif head.startswith(b"PVM2\n"):
        version, n_lines = 2, 3
    elif head.startswith(b"PVM3\n"):
        version, n_lines = 3, 3
    else:
        raise ReadError(path, f"not a PVM file: starts with {describe_bytes(head[:16])}, not 'PVM', 'PVM2' or "
                              "'PVM3' followed by a newline")
    pos = head.index(b"\n") + 1
    lines = []
    for _ in range(n_lines):
        end = head.find(b"\n", pos)
        if end < 0:
            raise ReadError(path, f"PVM{version if version > 1 else ''} header is incomplete (expected "
                                  f"{n_lines} lines after the magic)")
        lines.append(head[pos:end])
        pos = end + 1
    dim_tokens = lines[0].split()
    if len(dim_tokens) != 3:
        raise ReadError(path, f"PVM dimension line holds {len(dim_tokens)} fields, not three integers")
    dims = check_dims(path, [parse_int(path, t, "PVM dimension") for t in dim_tokens], "PVM dimensions")
    spacing = (1.0, 1.0, 1.0)
    if version >= 2:
        sp_tokens = lines[1].split()
        if len(sp_tokens) != 3:
            raise ReadError(path, f"PVM spacing line holds {len(sp_tokens)} fields, not three numbers")
        spacing = tuple(parse_float(path, t, "PVM spacing", positive=True) for t in sp_tokens)  # type: ignore
    bpv = parse_int(path, lines[-1], "PVM bytes per voxel")
    if bpv in (3, 4):
        raise ReadError(path, f"PVM with {bpv} components per voxel (RGB/RGBA volumes) is not supported; "
                              "only 1 (8-bit) and 2 (16-bit) bytes per voxel")
    if bpv not in (1, 2):
        raise ReadError(path, f"PVM bytes per voxel is {bpv}; must be 1 (8-bit) or 2 (16-bit)")
    return version, dims, spacing, bpv, pos  # type: ignore[return-value]


def read_pvm(path: PathLike) -> RegularVolume:
    """Read a PVM v1/v2/v3 volume into a RegularVolume (uint8 or native uint16), data shape (nx, ny, nz)."""
    size = file_size(path)
    head = read_bytes(path, _HEADER_LIMIT)
    version, dims, spacing, bpv, offset = parse_pvm_header(path, head)
    n_bytes = dims[0] * dims[1] * dims[2] * bpv  # Python ints: no overflow for absurd headers
    require_bytes(path, n_bytes, size - offset,
                  f"PVM header's {describe_dims(dims)} voxels of {bpv} byte{'s' if bpv > 1 else ''}")
    if version < 3 and size - offset > n_bytes:
        raise ReadError(path, f"PVM{version if version > 1 else ''} file holds {size - offset - n_bytes} bytes "
                              f"more than the {describe_dims(dims)} voxels of its header")
    raw = read_at(path, offset, n_bytes)
    data = np.frombuffer(raw, dtype=np.uint8 if bpv == 1 else ">u2")
    if bpv == 2:
        data = data.astype(np.uint16)  # big-endian on disk, native in memory
    volume = data.reshape(dims, order="F")
    return RegularVolume(volume, spacing=spacing, name="scalars", source=str(path))
