"""Cheap checks of the container formats under Exodus II, netCDF and CGNS, made before any VTK reader runs.

netCDF classic files (CDF-1, CDF-2, CDF-5) have their header parsed far enough to know where every variable's data
ends; HDF5 files (netCDF-4, Exodus on HDF5, CGNS/HDF5) have their superblock's end-of-file address read; CGNS ADF
files start with ``ADF Database Version`` and have their node tree walked (``volviz_vtk_readers.adf``). A file
shorter than its header says is truncated, and is refused with a ReadError before a VTK reader (which may crash on
it) sees it.
"""
from __future__ import annotations

import struct
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from volviz.io._checks import HDF5_SIGNATURE, check_file, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError, ReadWarning

NETCDF_MAGICS = (b"CDF\x01", b"CDF\x02", b"CDF\x05")
_NC_TYPE_SIZE = {1: 1, 2: 1, 3: 2, 4: 4, 5: 4, 6: 8, 7: 1, 8: 2, 9: 4, 10: 8, 11: 8}
_HEADER_LIMIT = 64 << 20  # a netCDF header larger than this is not parsed (only its magic is checked)
#: CF attributes whose text names other variables of the file (CF conventions §5, §7.1)
_REFERENCES = ("bounds", "coordinates")
#: CF attributes a reader interprets (units, axes, names, calendars): their text must be printable text
_CF_TEXT = ("units", "axis", "positive", "standard_name", "calendar", *_REFERENCES)


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
            raise EOFError(f"{n} bytes at byte {self.pos}")  # what was asked: a damaged count asks for too much
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
        """A name: UTF-8 text without control characters (the format's rule for names)."""
        n = self.count()
        raw = self.take(n + (-n % 4))[:n]
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            raise ValueError(f"a name at byte {self.pos - n - (-n % 4)} is not UTF-8 text") from None
        if not text or any(ord(ch) < 32 or ord(ch) == 127 for ch in text):
            raise ValueError(f"a name at byte {self.pos - n - (-n % 4)} is empty or holds control characters")
        return text

    def attributes(self) -> dict[str, str]:
        """The attribute list; returns the text attributes (type NC_CHAR) by name."""
        tag, n = self.int32(), self.count()
        if tag not in (0, 0x0C):
            raise ValueError(f"attribute list tag {tag:#x}")
        texts = {}
        for _ in range(n):
            name = self.name()
            nc_type, k = self.int32(), self.count()
            size = _NC_TYPE_SIZE.get(nc_type)
            if size is None:
                raise ValueError(f"attribute type {nc_type}")
            value = self.take(k * size + (-(k * size) % 4))
            if nc_type == 2:
                texts[name] = value[:k].rstrip(b"\0").decode("utf-8", "replace")
                if name in _CF_TEXT and not texts[name].isprintable():
                    raise ValueError(f"the {name!r} attribute at byte {self.pos - len(value)} is not printable text")
        return texts


@dataclass
class NetcdfVariable:
    """A variable of a netCDF classic header: its dimension names, shape (the record dimension's length is the
    number of records), type code (``_NC_TYPE_SIZE``), the byte offset of its data and whether it is a record
    variable."""

    name: str
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    nc_type: int
    begin: int
    record: bool
    units: str = ""


@dataclass
class NetcdfHeader:
    """What ``_netcdf_layout`` read: where the data end, the CF notes (``_cf_notes``), the dimensions' lengths and the
    variables by name."""

    end: int
    notes: list[str] = field(default_factory=list)
    dims: dict[str, int] = field(default_factory=dict)
    variables: dict[str, NetcdfVariable] = field(default_factory=dict)
    record_size: int = 0


def _netcdf_end(data: bytes) -> int:
    """The number of bytes the variables of a netCDF classic file reach (``_netcdf_layout``)."""
    return _netcdf_layout(data).end


def _netcdf_layout(data: bytes) -> NetcdfHeader:
    """The number of bytes the variables of a netCDF classic file reach, after checking the header's layout against
    itself (EOFError if ``data`` is too short to hold the header; ValueError naming the first inconsistency).
    Names are UTF-8 text without control characters; the CF attributes a reader interprets (``units``, ``axis``,
    ``positive``, ``standard_name``, ``calendar``, ``bounds``, ``coordinates``) are printable text, and ``bounds``
    and ``coordinates`` name variables the file holds (a damaged unit or name would make the reader take another
    variable for the grid).

    From the netCDF classic format specification (the ``vsize`` and ``begin`` of each variable): a variable's
    ``vsize`` is the product of its dimension lengths (the record dimension left out) times the size of its type,
    rounded up to 4 bytes, or 2^32-1 for a variable too large for the field; every ``begin`` lies after the header;
    the fixed-size variables do not overlap; the data ends with the last variable's unpadded values.

    Also returns notes on what a CF reader will misread although the file is valid netCDF (``_cf_notes``), the
    dimensions and the variables."""
    c = _Cursor(data, data[3])
    numrecs = c.count()
    tag, n_dims = c.int32(), c.count()
    if tag not in (0, 0x0A):
        raise ValueError(f"dimension list tag {tag:#x}")
    dims, dim_names = [], []
    for _ in range(n_dims):
        dim_names.append(c.name())
        dims.append(c.count())
    c.attributes()
    tag, n_vars = c.int32(), c.count()
    if tag not in (0, 0x0B):
        raise ValueError(f"variable list tag {tag:#x}")
    variables, references, cf_vars = [], [], []
    table: dict[str, NetcdfVariable] = {}
    for _ in range(n_vars):
        name = c.name()
        ids = [c.count() for _ in range(c.count())]
        texts = c.attributes()
        references += [(name, key, ref) for key in _REFERENCES for ref in texts.get(key, "").split()]
        nc_type = c.int32()
        vsize, begin = c.count(), c.offset()
        if any(i >= len(dims) for i in ids):
            raise ValueError(f"variable {name!r} uses dimension id {max(ids)} of {len(dims)}")
        size = _NC_TYPE_SIZE.get(nc_type) if nc_type <= (11 if c.version == 5 else 6) else None
        if size is None:
            raise ValueError(f"variable {name!r} has type {nc_type}")
        record = bool(ids) and dims[ids[0]] == 0
        exact = size
        for i in ids[1:] if record else ids:
            exact *= dims[i]
        if vsize not in (exact, exact + (-exact % 4)) and not (vsize == 0xFFFFFFFF and exact > 0xFFFFFFFB):
            raise ValueError(f"variable {name!r} has {exact} bytes by its dimensions but a size field of {vsize}")
        cf_vars.append((name, [dim_names[i] for i in ids], texts))
        variables.append((name, begin, exact, exact + (-exact % 4), record))
        table[name] = NetcdfVariable(name, tuple(dim_names[i] for i in ids),
                                     tuple(numrecs if dims[i] == 0 else dims[i] for i in ids), nc_type, begin, record,
                                     texts.get("units", ""))
    header_end = c.pos
    names = {v[0] for v in variables}
    for name, key, ref in references:
        if ref not in names:
            raise ValueError(f"variable {name!r} names {ref!r} in its {key!r} attribute, but the file has no variable "
                             "of that name")
    fixed = sorted((b, e, n) for n, b, e, _, r in variables if not r)
    records = [(b, e, p) for _, b, e, p, r in variables if r]
    for name, begin, *_ in variables:
        if begin < header_end:
            raise ValueError(f"variable {name!r} starts at byte {begin}, inside the {header_end}-byte header")
    for (b0, e0, n0), (b1, _, n1) in zip(fixed, fixed[1:]):
        if b0 + e0 > b1:
            raise ValueError(f"variables {n0!r} and {n1!r} overlap")
    end = max([header_end, *(b + e for b, e, _ in fixed)])
    record_size = records[0][1] if len(records) == 1 else sum(p for _, _, p in records)
    if records and numrecs not in (0, 0xFFFFFFFF, -1):
        end = max(end, max(b + e for b, e, _ in records) + (numrecs - 1) * record_size)
    return NetcdfHeader(end, _cf_notes(cf_vars), dict(zip(dim_names, dims)), table, record_size)


#: netCDF numeric type codes -> struct format (big-endian): byte, short, int, float, double, and CDF-5's
_NC_FORMATS = {1: "b", 3: "h", 4: "i", 5: "f", 6: "d", 7: "B", 8: "H", 9: "I", 10: "q", 11: "Q"}
_TIME_LIMIT = 1_000_000  # time coordinates longer than this are not checked value by value


def check_time_coordinates(path: Path, header: NetcdfHeader) -> None:
    """A CF time coordinate (CF §4.4: a coordinate variable, one dimension of its own name, whose ``units`` are
    "<unit> since <date>") holds finite values (else ReadError naming the variable, the index and the value) that
    increase (else a ReadWarning: VTK's reader keeps one step of equal or decreasing times and drops the others,
    so a damaged value would silently shorten the series)."""
    import math

    for var in header.variables.values():
        if var.dims != (var.name,) or " since " not in var.units or var.nc_type not in _NC_FORMATS \
                or not 1 < var.shape[0] <= _TIME_LIMIT:
            continue
        fmt, size = ">" + _NC_FORMATS[var.nc_type], _NC_TYPE_SIZE[var.nc_type]
        step = header.record_size if var.record else size
        with open(path, "rb") as fh:
            values = []
            for k in range(var.shape[0]):
                fh.seek(var.begin + k * step)
                values.append(struct.unpack(fmt, fh.read(size))[0])
        for k, v in enumerate(values):
            if not math.isfinite(v):
                raise ReadError(path, f"netCDF: time coordinate {var.name!r} holds {v} at index {k} (of "
                                      f"{len(values)}): the file is damaged")
        for k in range(len(values) - 1):
            if not values[k] < values[k + 1]:
                warnings.warn(ReadWarning(
                    f"{path}: time coordinate {var.name!r} does not increase: {values[k]:g} at index {k}, "
                    f"{values[k + 1]:g} at index {k + 1} (of {len(values)}); the reader keeps one step of equal or "
                    "decreasing times, so the series shown may be shorter than the file's"), stacklevel=3)
                break


def _cf_notes(variables: list[tuple[str, list[str], dict[str, str]]]) -> list[str]:
    """What a CF reader will misread in a valid netCDF file: a variable with cell bounds (CF §7.1: the ``bounds``
    attribute belongs to coordinates) that is neither a coordinate variable (one dimension of its own name, NUG §2.3.1,
    CF §1.3) nor an auxiliary coordinate named in a ``coordinates`` attribute (CF §5). The file may be valid (CF does
    not forbid ``bounds`` elsewhere), but a coordinate whose dimension or name was changed looks exactly like this, and
    the reader then takes it for data: the grid shown is another one than the file's author meant."""
    auxiliary = {ref for _, _, texts in variables for ref in texts.get("coordinates", "").split()}
    notes = []
    for name, dims, texts in variables:
        bounds = texts.get("bounds", "").strip()
        if not bounds or dims == [name] or name in auxiliary:
            continue
        on = f"dimension {dims[0]!r}" if len(dims) == 1 else f"dimensions {tuple(dims)!r}"
        notes.append(f"variable {name!r} has cell bounds ({bounds!r}) as a coordinate has, but it is not one: it is on "
                     f"{on}, not on a dimension of its own name, and no variable names it in a 'coordinates' "
                     "attribute (CF §5, §7.1); the reader takes it for data, so the grid shown may not be the one "
                     "the file's data variables are on")
    return notes


def _hdf5_end(path: PathLike, head: bytes) -> int:
    """The end-of-file address an HDF5 superblock records; ReadError when the superblock is cut short or of a
    version HDF5 does not write (0 to 3: HDF5 File Format Specification, "Superblock")."""
    version = head[8] if len(head) > 8 else -1
    if version in (0, 1) and len(head) > 13:
        width = head[13]
        at = 24 + (4 if version == 1 else 0) + 2 * width
    elif version in (2, 3) and len(head) > 9:
        width = head[9]
        at = 12 + 2 * width
    elif version == -1 or len(head) < 48:
        raise ReadError(path, f"the file holds {len(head)} bytes, fewer than an HDF5 superblock: it is truncated")
    else:
        raise ReadError(path, f"HDF5 superblock version {version} is not one HDF5 writes (0 to 3): the file is "
                              "damaged")
    if width not in (4, 8):
        raise ReadError(path, f"HDF5 superblock gives {width}-byte offsets")
    if len(head) < at + width:
        raise ReadError(path, f"the file holds {len(head)} bytes and ends inside its HDF5 superblock (the end-of-file "
                              f"address is at bytes {at} to {at + width}): it is truncated")
    return int.from_bytes(head[at:at + width], "little")


def netcdf_header(path: PathLike, what: str, head: bytes | None = None) -> NetcdfHeader | None:
    """The checked header of the netCDF classic file ``path`` (``_netcdf_layout``; ``head``: its first bytes if read
    already); None for a header over ``_HEADER_LIMIT`` bytes, which is not parsed. ReadError when the header
    contradicts itself or the file is shorter than it says."""
    p = Path(path)
    size = p.stat().st_size
    data = read_bytes(p, 65536) if head is None else head
    while True:
        try:
            header = _netcdf_layout(data)
            break
        except EOFError as exc:
            if len(data) >= min(size, _HEADER_LIMIT):
                if size <= _HEADER_LIMIT:
                    raise ReadError(p, f"{what}: the netCDF header runs past the end of the file ({size} bytes; it "
                                       f"asks for {exc}): the file is truncated or a count in its header is "
                                       "damaged") from None
                return None
            data = read_bytes(p, min(size, 4 * len(data)))
        except (ValueError, struct.error) as exc:
            raise ReadError(p, f"{what}: malformed netCDF header ({exc})") from None
    if header.end > size:
        raise ReadError(p, f"{what}: the netCDF header places data up to byte {header.end}, but the file holds "
                           f"{size} bytes: the file is truncated")
    return header


def check_container(path: PathLike, what: str, netcdf: bool = True, hdf5: bool = True, adf: bool = False,
                    cf: bool = False) -> Path:
    """Check ``path`` is a regular file in one of the allowed containers and not shorter than its header says. With
    ``cf`` (a file read by CF conventions), a netCDF classic header's ``_cf_notes`` are emitted as ReadWarnings."""
    p = check_file(path)
    head = read_bytes(p, 65536)
    if netcdf and head[:4] in NETCDF_MAGICS:
        header = netcdf_header(p, what, head)
        for note in header.notes if cf and header is not None else []:
            warnings.warn(ReadWarning(f"{p}: {note}"), stacklevel=2)
        if cf and header is not None:
            check_time_coordinates(p, header)
        return p
    if hdf5 and head.startswith(HDF5_SIGNATURE):
        end, size = _hdf5_end(p, head), p.stat().st_size
        if end > size:
            raise ReadError(p, f"{what}: the HDF5 superblock says the file is {end} bytes, but it holds {size}: the "
                               "file is truncated")
        return p
    if adf and b"ADF Database Version" in head[:48]:
        from volviz_vtk_readers.adf import check_adf

        check_adf(p)  # the whole node tree: tags, addresses, dimensions against data chunks
        return p
    expected = [name for ok, name in ((netcdf, "netCDF (CDF\\x01, CDF\\x02, CDF\\x05)"), (hdf5, "HDF5"),
                                      (adf, "CGNS ADF")) if ok]
    raise ReadError(p, f"not a {what} file: its content is {describe_bytes(head)}, expected {' or '.join(expected)}")
