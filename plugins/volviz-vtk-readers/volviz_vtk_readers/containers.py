"""Cheap checks of the container formats under Exodus II, netCDF and CGNS, made before any VTK reader runs.

netCDF classic files (CDF-1, CDF-2, CDF-5) have their header parsed far enough to know where every variable's data
ends; HDF5 files (netCDF-4, Exodus on HDF5, CGNS/HDF5) have their superblock's end-of-file address read; CGNS ADF
files start with ``ADF Database Version``. A file shorter than its header says is truncated, and is refused with a
ReadError before a VTK reader (which may crash on it) sees it.
"""
from __future__ import annotations

import struct
from pathlib import Path

from volviz.io._checks import check_file, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
NETCDF_MAGICS = (b"CDF\x01", b"CDF\x02", b"CDF\x05")
_NC_TYPE_SIZE = {1: 1, 2: 1, 3: 2, 4: 4, 5: 4, 6: 8, 7: 1, 8: 2, 9: 4, 10: 8, 11: 8}
_HEADER_LIMIT = 64 << 20  # a netCDF header larger than this is not parsed (only its magic is checked)


def is_netcdf(head: bytes) -> bool:
    return head[:4] in NETCDF_MAGICS or head.startswith(HDF5_SIGNATURE)


def is_cgns(head: bytes) -> bool:
    return b"ADF Database Version" in head[:48] or head.startswith(HDF5_SIGNATURE)


class _Cursor:
    """Big-endian reads over a netCDF classic header; running off the end raises EOFError."""

    def __init__(self, data: bytes, version: int) -> None:
        self.data, self.pos, self.version = data, 4, version

    def take(self, n: int) -> bytes:
        if self.pos + n > len(self.data):
            raise EOFError
        out = self.data[self.pos:self.pos + n]
        self.pos += n
        return out

    def int32(self) -> int:
        return struct.unpack(">i", self.take(4))[0]

    def count(self) -> int:  # NON_NEG: 64-bit in CDF-5
        return struct.unpack(">q", self.take(8))[0] if self.version == 5 else struct.unpack(">I", self.take(4))[0]

    def offset(self) -> int:  # OFFSET: 64-bit in CDF-2 and CDF-5
        return struct.unpack(">q", self.take(8))[0] if self.version in (2, 5) else struct.unpack(">I", self.take(4))[0]

    def name(self) -> str:
        n = self.count()
        return self.take(n + (-n % 4))[:n].decode("utf-8", "replace")

    def attributes(self) -> None:
        tag, n = self.int32(), self.count()
        if tag not in (0, 0x0C):
            raise ValueError(f"attribute list tag {tag:#x}")
        for _ in range(n):
            self.name()
            nc_type, k = self.int32(), self.count()
            size = _NC_TYPE_SIZE.get(nc_type)
            if size is None:
                raise ValueError(f"attribute type {nc_type}")
            self.take(k * size + (-(k * size) % 4))


def _netcdf_end(data: bytes) -> int:
    """The number of bytes the variables of a netCDF classic file reach (EOFError if ``data`` is too short)."""
    c = _Cursor(data, data[3])
    numrecs = c.count()
    tag, n_dims = c.int32(), c.count()
    if tag not in (0, 0x0A):
        raise ValueError(f"dimension list tag {tag:#x}")
    dims = []
    for _ in range(n_dims):
        c.name()
        dims.append(c.count())
    c.attributes()
    tag, n_vars = c.int32(), c.count()
    if tag not in (0, 0x0B):
        raise ValueError(f"variable list tag {tag:#x}")
    fixed_end, records = c.pos, []
    for _ in range(n_vars):
        c.name()
        ids = [c.count() for _ in range(c.count())]
        c.attributes()
        c.int32()  # nc_type
        vsize, begin = c.count(), c.offset()
        if any(i >= len(dims) for i in ids):
            raise ValueError(f"variable uses dimension id {max(ids)} of {len(dims)}")
        if ids and dims[ids[0]] == 0:
            records.append((begin, vsize))
        else:
            fixed_end = max(fixed_end, begin + vsize - 3)  # the last variable's padding may be missing
    if records and numrecs not in (0, 0xFFFFFFFF, -1):
        record_size = sum(v for _, v in records)
        fixed_end = max(fixed_end, max(b + v for b, v in records) + (numrecs - 1) * record_size - 3)
    return fixed_end


def _hdf5_end(path: PathLike, head: bytes) -> int:
    """The end-of-file address an HDF5 superblock records (0 when the layout is not one we know)."""
    version = head[8] if len(head) > 8 else -1
    if version in (0, 1) and len(head) >= 48:
        width = head[13]
        at = 24 + (4 if version == 1 else 0) + 2 * width
    elif version in (2, 3) and len(head) >= 48:
        width = head[9]
        at = 12 + 2 * width
    else:
        return 0
    if width not in (4, 8):
        raise ReadError(path, f"HDF5 superblock gives {width}-byte offsets")
    return int.from_bytes(head[at:at + width], "little")


def check_container(path: PathLike, what: str, netcdf: bool = True, hdf5: bool = True, adf: bool = False) -> Path:
    """Check ``path`` is a regular file in one of the allowed containers and not shorter than its header says."""
    p = check_file(path)
    size = p.stat().st_size
    head = read_bytes(p, 65536)
    if netcdf and head[:4] in NETCDF_MAGICS:
        data = head
        while True:
            try:
                end = _netcdf_end(data)
                break
            except EOFError:
                if len(data) >= min(size, _HEADER_LIMIT):
                    if size <= _HEADER_LIMIT:
                        raise ReadError(p, f"{what}: the netCDF header runs past the end of the file ({size} "
                                           "bytes): the file is truncated") from None
                    return p
                data = read_bytes(p, min(size, 4 * len(data)))
            except (ValueError, struct.error) as exc:
                raise ReadError(p, f"{what}: malformed netCDF header ({exc})") from None
        if end > size:
            raise ReadError(p, f"{what}: the netCDF header places data up to byte {end}, but the file holds {size} "
                               "bytes: the file is truncated")
        return p
    if hdf5 and head.startswith(HDF5_SIGNATURE):
        end = _hdf5_end(p, head)
        if end > size:
            raise ReadError(p, f"{what}: the HDF5 superblock says the file is {end} bytes, but it holds {size}: the "
                               "file is truncated")
        return p
    if adf and b"ADF Database Version" in head[:48]:
        return p
    expected = [name for ok, name in ((netcdf, "netCDF (CDF\\x01, CDF\\x02, CDF\\x05)"), (hdf5, "HDF5"),
                                      (adf, "CGNS ADF")) if ok]
    raise ReadError(p, f"not a {what} file: its content is {describe_bytes(head)}, expected {' or '.join(expected)}")
