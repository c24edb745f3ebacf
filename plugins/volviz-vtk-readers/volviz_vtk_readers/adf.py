"""Structure checks of CGNS files in ADF, the CGNS library's own container, made before VTK's vtkCGNSReader opens them.

The CGNS library's ADF core trusts what a file says: a node's dimensions size the buffers that are allocated for its
data, disk pointers are followed without comparing them with the file's length, a sub-node table is read into an
array sized by another field. A damaged file then crashes, aborts, exhausts memory or hangs the reader. ``check_adf``
walks the whole node tree first, reading the fixed-size headers and tables (and of the data only the few numbers
named at the end), and refuses with a ReadError that names the node and the problem:

- a file header without the ``ADF Database Version`` string (whole: ADF copies it up to a NUL byte; of a minor
  version the CGNS library reads) or its six boundary tags (``AdF0`` .. ``AdF5``), of an ADF version other than A
  (disk pointers and dimensions written as ASCII hexadecimal) or B (as binary integers in the file's byte order), of
  a numeric format other than IEEE big- or little-endian or Cray, with implausible type sizes, or whose end-of-file
  pointer lies past the end of the file (a truncated file); a free-chunk table without its tags;
- a node header lying partly outside the file or without its ``NoDe`` / ``TaiL`` tags; any field that ADF parses as
  hexadecimal and that is not (unused dimensions and sub-node table entries included: ADF parses them too); a disk
  pointer whose offset exceeds the 4096-byte block;
- more than 12 dimensions, a dimension of 0, a value in an unused dimension field (ADF writes 0), a data type ADF
  does not know (it knows MT, I4, I8, U4, U8, R4, R8, X4, X8, C1, B1 and LK), an MT (no data) node with dimensions or
  data;
- data that the node's dimensions times its type size add up to but that its data chunks do not hold: one chunk
  (``DaTa`` .. ``dEnD``) or a data-chunk table (``DCtb`` .. ``dcTE``) of exactly as many chunks as the node counts,
  each inside the file, with its tags; data declared and not stored at all (the file can hold no more data than its
  own size, so nothing a node claims is allocated);
- a sub-node table (``SNTb`` .. ``snTE``) outside the file, of another size than the node's entry count says, with
  fewer entries than the node's sub-node count, or with a node listed beyond that count (ADF blanks unused entries);
  a child whose header gives another name than its parent's table;
- a node reached twice (a sub-node table pointing back into the tree: a cycle), or more nodes than the file can hold;
- a label that is not text, or that is one or two bits away from one of the CGNS library's labels (``Zone_t``,
  ``DataArray_t``, ...: the CGNS library finds nodes by label, so a damaged label silently hides a zone).

Then the few numbers in the data that VTK allocates by (CGNS on top of ADF; ``_Walk.sizes_of_zones``): a base's cell
and physical dimensions (1 to 3), a zone's vertex and cell counts (at least one vertex each way, a structured zone one
cell fewer than vertices each way), and the coordinate arrays, which must hold one value per vertex.

The layout is the one the CGNS library's ADF core reads and writes, learned from its sources: ``src/adf/ADF.h``
(name, label and data-type lengths, 12 dimensions at most), ``src/adf/ADF_internals.h`` (the sizes of the file header,
free-chunk table, node header, disk pointer and tags; the 4096-byte disk block) and ``src/adf/ADF_internals.c`` (the
tables of its opening comment; ``ADFI_read_file_header``, ``ADFI_read_node_header``, ``ADFI_read_disk_pointer``,
``ADFI_read_sub_node_table``, ``ADFI_delete_from_sub_node_table``, ``ADFI_read_data_chunk_table``,
``ADFI_read_data_chunk``, ``ADFI_evaluate_datatype``), with ``src/adf/ADF_interface.c`` (``ADF_Database_Open``: the
version string and its minor version; ``ADF_Read_All_Data``: a node's data size from its type and dimensions;
``ADF_Put_Dimension_Information``: dimensions of at least 1, unused ones zeroed). The labels are those
``src/cgnslib.c`` and ``src/cgns_internals.c`` write.

Linked nodes (type LK) are checked as nodes; the files they link to are not opened. A file of up to 256 MB is read
into memory once; of a larger one only the headers and tables visited are read.
"""
from __future__ import annotations

import re
from collections import defaultdict
from math import prod
from pathlib import Path
from typing import BinaryIO, Literal, NamedTuple, NoReturn, Union

from volviz.io._checks import check_file
from volviz.io.errors import PathLike, ReadError, human_bytes

BLOCK = 4096            # bytes of a disk block: a disk pointer is (block, offset in the block)
FILE_HEADER = 186
FREE_CHUNK_TABLE = 80
NODE_HEADER = 246
TAG = 4
POINTER = 12
NAME = 32
SUB_NODE_ENTRY = NAME + POINTER
CHUNK_HEAD = TAG + POINTER  # a tag and the pointer to the end tag open every variable-size chunk and table
MAX_DIMENSIONS = 12
ADF_MINOR = 2           # the minor version of the files the CGNS library writes (B02012) and reads
IN_MEMORY = 256 << 20

_HEADER_TAGS = ((32, b"AdF0"), (64, b"AdF1"), (96, b"AdF2"), (102, b"AdF3"), (130, b"AdF4"), (182, b"AdF5"))
#: the file header's type sizes (two hex digits each from byte 106, then six pointer sizes) and the values a
#: machine ADF knows (IEEE 32/64-bit, Cray) writes
_TYPE_SIZES = {"char": (1,), "short": (2, 8), "int": (4, 8), "long": (4, 8), "float": (4, 8), "double": (8,)}
#: each ADF data type: the type size it is made of (None: one byte), and how many of them
_DATA_TYPES = {b"MT": (None, 0), b"I4": ("int", 1), b"U4": ("int", 1), b"I8": ("long", 1), b"U8": ("long", 1),
               b"R4": ("float", 1), b"R8": ("double", 1), b"X4": ("float", 2), b"X8": ("double", 2),
               b"C1": ("char", 1), b"LK": ("char", 1), b"B1": (None, 1)}
_KNOWN_TYPES = ", ".join(t.decode() for t in _DATA_TYPES)
#: the labels the CGNS library gives nodes (src/cgnslib.c, src/cgns_internals.c), and ADF's root node's
_LABELS = {f"{kind}_t".encode() for kind in (
    "AdditionalExponents AdditionalFamilyName AdditionalUnits ArbitraryGridMotion AreaType Area AverageInterfaceType "
    "AverageInterface Axisymmetry BCDataSet BCData BCProperty BC BaseIterativeData CGNSBase CGNSLibraryVersion "
    "ChemicalKineticsModel ConvergenceHistory DataArray DataClass DataConversion Descriptor DimensionalExponents "
    "DimensionalUnits DiscreteData EMConductivityModel EMElectricFieldModel EMMagneticFieldModel Elements "
    "FamilyBCDataSet FamilyBC FamilyName Family FlowEquationSet FlowSolution GasModel GeometryEntity GeometryFile "
    "GeometryFormat GeometryReference GoverningEquations Gravity GridConnectivity1to1 GridConnectivityProperty "
    "GridConnectivityType GridConnectivity GridCoordinates GridLocation IndexArray IndexRange IntegralData Model "
    "Ordinal OversetHoles ParticleBreakupModel ParticleCollisionModel ParticleCoordinates ParticleEquationSet "
    "ParticleForceModel ParticleGoverningEquations ParticleIterativeData ParticleModel ParticlePhaseChangeModel "
    "ParticleSolution ParticleWallInteractionModel ParticleZone Periodic ReferenceState RigidGridMotion Rind "
    "RotatingCoordinates SimulationType StructuredDonor ThermalConductivityModel ThermalRelaxationModel "
    "TurbulenceClosureModel TurbulenceClosure TurbulenceModel UnstructuredDonor UserDefinedData ViscosityModel "
    "WallFunctionType WallFunction ZoneBC ZoneGridConnectivity ZoneIterativeData ZoneSubRegion ZoneType Zone").split()}
_LABELS |= {b'"int[IndexDimension]"', b'"int[1+...+IndexDimension]"', b'"int"', b"Root Node of ADF File"}
#: each label as the blank-filled 32-byte field, as an integer, to count the bits in which a label differs from it
_LABEL_BITS = {label: int.from_bytes(label.ljust(32), "big") for label in _LABELS}
_HEX = re.compile(rb"[0-9A-Fa-f]+")


def _name(raw: bytes) -> str:
    """A blank-filled node name as text, or ``?`` when it is not printable ASCII (never quoted as bytes)."""
    text = raw.rstrip(b" \0")
    return text.decode("ascii") if text and all(32 <= b < 127 for b in text) else "?"


class _Node(NamedTuple):
    """What the CGNS checks need of a node: where it is, its label, data type, dimensions and data (offset, bytes)."""

    path: str
    parent: str
    label: bytes
    dtype: bytes
    dims: list[int]
    spans: list[tuple[int, int]]


#: the nodes the CGNS checks look at (the others are checked as ADF nodes only)
_SIZED = {b"CGNSBase_t", b"Zone_t", b"ZoneType_t", b"GridCoordinates_t", b"DataArray_t", b"Rind_t"}


class _File:
    """The file's bytes: all in memory up to IN_MEMORY bytes, else read where asked."""

    def __init__(self, path: Path, size: int) -> None:
        self.source: Union[bytes, BinaryIO] = path.read_bytes() if size <= IN_MEMORY else open(path, "rb")
        self.size = len(self.source) if isinstance(self.source, bytes) else size

    def at(self, offset: int, count: int) -> bytes:
        if isinstance(self.source, bytes):
            return self.source[offset:offset + count]
        self.source.seek(offset)
        return self.source.read(count)

    def close(self) -> None:
        if not isinstance(self.source, bytes):
            self.source.close()


class _Walk:
    """The checks of one ADF file, header first, then every node from the root."""

    def __init__(self, path: Path, file: _File) -> None:
        self.path, self.file, self.size = path, file, file.size
        self.binary = False
        self.order: Literal["little", "big"] = "big"
        self.sizes: dict[str, int] = {}
        self.nodes: dict[str, _Node] = {}

    def fail(self, problem: str) -> NoReturn:
        raise ReadError(self.path, f"CGNS ADF: {problem}")

    def damaged(self, problem: str) -> NoReturn:
        self.fail(f"{problem}: the file is damaged")

    def span(self, at: int, count: int, what: str) -> bytes:
        """``count`` bytes at byte ``at``, which must lie inside the file."""
        if at < 0 or at + count > self.size:
            self.fail(f"{what} at byte {at} reaches past the end of the file ({self.size} bytes): the file is "
                      "truncated or damaged")
        raw = self.file.at(at, count)
        if len(raw) < count:  # the file shrank while being checked
            self.fail(f"{what} at byte {at} could not be read: the file is truncated")
        return raw

    def hex(self, raw: bytes, what: str) -> int:
        if not _HEX.fullmatch(raw):
            self.damaged(f"{what} is not a hexadecimal number")
        return int(raw, 16)

    def pointer(self, raw: bytes, what: str) -> int:
        """The byte addressed by a disk pointer: 8 bytes of block, 4 of offset in the block."""
        if self.binary:
            block, offset = int.from_bytes(raw[:8], self.order), int.from_bytes(raw[8:12], self.order)
        else:
            block, offset = self.hex(raw[:8], what), self.hex(raw[8:12], what)
        if offset > BLOCK:
            self.damaged(f"{what} gives an offset of {offset} in a {BLOCK}-byte block")
        return block * BLOCK + offset

    def tags(self, at: int, start: bytes, what: str) -> int:
        """Check the start tag of the chunk or table at ``at`` and the end tag its pointer leads to; return where
        the end tag is."""
        head = self.span(at, CHUNK_HEAD, what)
        if head[:TAG] != start:
            self.damaged(f"{what} at byte {at} lacks its {start.decode()} start tag")
        end = self.pointer(head[TAG:], f"the end pointer of {what}")
        if end < at + CHUNK_HEAD:
            self.damaged(f"{what} at byte {at} ends (byte {end}) before its own start")
        return end

    # -- the file header -------------------------------------------------------------------------------------------
    def header(self) -> int:
        """Check the file header and the free-chunk table; the root node's address."""
        least = FILE_HEADER + FREE_CHUNK_TABLE + NODE_HEADER
        if self.size < least:
            self.fail(f"the file ({self.size} bytes) is shorter than its header, free-chunk table and root node "
                      f"({least} bytes): the file is truncated")
        head = self.file.at(0, FILE_HEADER)
        if head[4:24] != b"ADF Database Version" or b"\0" in head[:32] or head[28:29] == b">":
            self.damaged("the file header does not give an ADF database version")  # ADF copies it up to a NUL byte
        minor = self.hex(head[26:28], "the file header's ADF minor version")
        if minor > ADF_MINOR:
            self.fail(f"the file header gives ADF minor version {minor}, newer than the CGNS library reads "
                      f"({ADF_MINOR}): the file is damaged or written by a newer library")
        for at, tag in _HEADER_TAGS:
            if head[at:at + TAG] != tag:
                self.damaged(f"the file header lacks its {tag.decode()} boundary tag at byte {at}")
        if head[25] not in b"AB":
            self.damaged("the file header gives an ADF version other than A or B")
        self.binary = head[25] == ord("B")
        numeric, os_size = chr(head[100]), chr(head[101])
        if numeric not in ("BLC" if self.binary else "BLCN") or os_size not in "BL":
            self.damaged("the file header gives a numeric format ADF does not know")
        self.order = "little" if numeric == "L" else "big"
        for i, (kind, allowed) in enumerate(_TYPE_SIZES.items()):
            self.sizes[kind] = self.hex(head[106 + 2 * i:108 + 2 * i], f"the file header's size of {kind}")
            if self.sizes[kind] not in allowed:
                self.damaged(f"the file header gives sizeof({kind}) = {self.sizes[kind]}, not "
                             f"{' or '.join(map(str, allowed))}")
        for i in range(6, 12):  # the pointer sizes: parsed, not used
            self.hex(head[106 + 2 * i:108 + 2 * i], "the file header's pointer size")
        root = self.pointer(head[134:146], "the file header's root-node pointer")
        end = self.pointer(head[146:158], "the file header's end-of-file pointer")
        self.pointer(head[158:170], "the file header's free-chunk pointer")
        self.pointer(head[170:182], "the file header's extra pointer")
        if end >= self.size:
            self.fail(f"the file header says the file's data reach byte {end}, but the file holds {self.size} bytes "
                      f"({human_bytes(self.size)}): the file is truncated")
        free = self.file.at(FILE_HEADER, FREE_CHUNK_TABLE)
        if free[:TAG] != b"fCbt" or free[-TAG:] != b"Fcte":
            self.damaged(f"the free-chunk table at byte {FILE_HEADER} lacks its fCbt/Fcte tags")
        return root

    # -- the nodes -------------------------------------------------------------------------------------------------
    def tree(self, root: int) -> int:
        """Visit every node from the root; the number of nodes."""
        limit = self.size // NODE_HEADER
        seen: set[int] = set()
        stack: list[tuple[int, bytes | None, str]] = [(root, None, "")]
        while stack:
            at, listed, parent = stack.pop()
            if at in seen:
                self.damaged(f"the sub-node table of {self.where(parent)} lists the node at byte {at}, which is "
                             "already in the tree (a cycle)")
            seen.add(at)
            if len(seen) > limit:
                self.damaged(f"the node tree holds more than {limit} nodes, more than its {self.size} bytes can hold")
            stack.extend(self.node(at, listed, parent))
        return len(seen)

    @staticmethod
    def where(path: str, at: int | None = None) -> str:
        place = f"node '{path}'" if path else "the root node"
        return place if at is None else f"{place} (byte {at})"

    def node(self, at: int, listed: bytes | None, parent: str) -> list[tuple[int, bytes, str]]:
        """Check the node at ``at`` (``listed``: its name in the parent's sub-node table); its children."""
        path = "" if listed is None else f"{parent}/{_name(listed)}".lstrip("/")
        where = self.where(path, at)
        raw = self.span(at, NODE_HEADER, f"the header of {self.where(path)}")
        if raw[:TAG] != b"NoDe" or raw[-TAG:] != b"TaiL":
            self.damaged(f"{where} lacks its NoDe/TaiL boundary tags (the sub-node table of "
                         f"{self.where(parent)} points to something else)" if listed is not None else
                         f"{where} lacks its NoDe/TaiL boundary tags")
        self.label(where, raw[36:68])
        if listed is not None and raw[TAG:TAG + NAME].rstrip(b" \0") != listed.rstrip(b" \0"):
            self.damaged(f"{where} gives another name in its header than in the sub-node table of "
                         f"{self.where(parent)}")
        n_sub = self.hex(raw[68:76], f"the sub-node count of {where}")
        entries = self.hex(raw[76:84], f"the sub-node table size of {where}")
        table = self.pointer(raw[84:96], f"the sub-node table pointer of {where}")
        n_dims = self.hex(raw[128:130], f"the number of dimensions of {where}")
        if n_dims > MAX_DIMENSIONS:
            self.damaged(f"{where} has {n_dims} dimensions; ADF allows {MAX_DIMENSIONS} at most")
        if self.binary:
            dims = [int.from_bytes(raw[130 + 8 * i:138 + 8 * i], self.order) for i in range(MAX_DIMENSIONS)]
        else:  # ADF parses all twelve, used or not
            dims = [self.hex(raw[130 + 8 * i:138 + 8 * i], f"dimension {i + 1} of {where}")
                    for i in range(MAX_DIMENSIONS)]
        if any(dims[n_dims:]):
            self.damaged(f"{where} has {n_dims} dimensions but a value in an unused dimension field (ADF writes 0)")
        dims = dims[:n_dims]
        n_chunks = self.hex(raw[226:230], f"the data chunk count of {where}")
        chunks = self.pointer(raw[230:242], f"the data pointer of {where}")
        dtype, label = raw[96:128].rstrip(b" \0").upper(), raw[36:68].rstrip(b" \0")
        spans = self.data(where, dtype, dims, n_chunks, chunks)
        if label in _SIZED and path not in self.nodes:
            self.nodes[path] = _Node(path, parent, label, dtype, dims, spans)
        return self.children(where, path, n_sub, entries, table)

    def label(self, where: str, raw: bytes) -> None:
        """A label that is not text, or that differs from one of CGNS's labels in one or two bits, is damaged (the
        CGNS library reads nodes by label: a damaged one hides its node and everything below it). Other labels pass:
        ADF allows any."""
        text = raw.rstrip(b" \0")
        if text in _LABELS:
            return
        if not all(32 <= b < 127 for b in text):
            self.damaged(f"{where} has a label that is not text")
        value = int.from_bytes(raw, "big")
        for label, bits in _LABEL_BITS.items():
            if (value ^ bits).bit_count() <= 2:
                self.damaged(f"{where} has a label one or two bits away from CGNS's {label.decode()}")

    def data(self, where: str, dtype: bytes, dims: list[int], n_chunks: int, chunks: int) -> list[tuple[int, int]]:
        """The node's dimensions and data type against the data chunks it points to; (offset, bytes) of each."""
        if dtype not in _DATA_TYPES:
            self.damaged(f"{where} has a data type ADF does not know (not one of {_KNOWN_TYPES})")
        if 0 in dims:
            self.damaged(f"{where} has a dimension of 0 (ADF requires at least 1)")
        if dtype == b"MT":
            if dims or n_chunks:
                self.damaged(f"{where} has no data type (MT) but {len(dims)} dimensions and {n_chunks} data chunks")
            return []
        kind, count = _DATA_TYPES[dtype]
        item = count * (self.sizes[kind] if kind else 1)
        expected = item * prod(dims) if dims else 0
        shape = f"{' x '.join(map(str, dims))} values of {item} bytes ({dtype.decode()})"
        if expected > self.size:
            self.damaged(f"{where} claims {expected} bytes ({human_bytes(expected)}) of data ({shape}), but the whole "
                         f"file holds {self.size} bytes ({human_bytes(self.size)})")
        if n_chunks == 0:
            if expected:
                self.damaged(f"{where} declares {expected} bytes of data ({shape}) but stores none")
            return []
        spans = [(chunks + CHUNK_HEAD, self.chunk(chunks, where))] if n_chunks == 1 else \
            self.chunk_table(chunks, n_chunks, where)
        held = sum(n for _, n in spans)
        if expected > held:
            self.damaged(f"{where} claims {expected} bytes of data ({shape}), but its data chunks hold {held} bytes")
        return spans

    def chunk(self, at: int, where: str) -> int:
        """The bytes of data the chunk at ``at`` holds, its tags checked."""
        what = f"the data chunk of {where}"
        end = self.tags(at, b"DaTa", what)
        if self.span(end, TAG, f"the end tag of {what}") != b"dEnD":
            self.damaged(f"{what} (byte {at}) lacks its dEnD end tag at byte {end}")
        return end - at - CHUNK_HEAD

    def chunk_table(self, at: int, n_chunks: int, where: str) -> list[tuple[int, int]]:
        """(offset, bytes) of the data in each chunk of the data-chunk table at ``at``, each chunk checked."""
        what = f"the data-chunk table of {where}"
        end = self.tags(at, b"DCtb", what)
        if end - at - CHUNK_HEAD != n_chunks * 2 * POINTER:
            self.damaged(f"{what} (byte {at}) holds {(end - at - CHUNK_HEAD) / (2 * POINTER):g} entries, not the "
                         f"{n_chunks} data chunks the node counts")
        if self.span(end, TAG, f"the end tag of {what}") != b"dcTE":
            self.damaged(f"{what} (byte {at}) lacks its dcTE end tag at byte {end}")
        body = self.span(at + CHUNK_HEAD, n_chunks * 2 * POINTER, what)
        spans = []
        for i in range(n_chunks):
            start = self.pointer(body[24 * i:24 * i + 12], f"entry {i + 1} of {what}")
            stop = self.pointer(body[24 * i + 12:24 * i + 24], f"entry {i + 1} of {what}")
            listed = stop - start - CHUNK_HEAD
            if listed < 0 or listed > self.chunk(start, where):
                self.damaged(f"entry {i + 1} of {what} gives a data chunk of {listed} bytes, not the bytes its chunk "
                             "holds")
            spans.append((start + CHUNK_HEAD, listed))
        return spans

    def children(self, where: str, path: str, n_sub: int, entries: int, table: int) -> list[tuple[int, bytes, str]]:
        """The (address, listed name, parent path) of each child, from the node's sub-node table."""
        if n_sub == entries == 0:
            return []
        if n_sub > entries:
            self.damaged(f"{where} counts {n_sub} sub-nodes but its sub-node table has room for {entries}")
        what = f"the sub-node table of {where}"
        end = self.tags(table, b"SNTb", what)
        if end - table - CHUNK_HEAD != entries * SUB_NODE_ENTRY:
            self.damaged(f"{what} (byte {table}) holds {end - table - CHUNK_HEAD} bytes, not the {entries} entries of "
                         f"{SUB_NODE_ENTRY} bytes the node counts")
        if self.span(end, TAG, f"the end tag of {what}") != b"snTE":
            self.damaged(f"{what} (byte {table}) lacks its snTE end tag at byte {end}")
        body = self.span(table + CHUNK_HEAD, entries * SUB_NODE_ENTRY, what)
        found = []
        for i in reversed(range(entries)):  # ADF reads the unused entries too; reversed: the stack visits in order
            entry = body[i * SUB_NODE_ENTRY:(i + 1) * SUB_NODE_ENTRY]
            child = self.pointer(entry[NAME:], f"entry {i + 1} of {what}")
            if i < n_sub:
                found.append((child, entry[:NAME], path))
            elif child not in (0, BLOCK):  # ADF blanks an unused entry (block 0, offset 0 or 4096)
                self.damaged(f"{what} lists a node in entry {i + 1}, beyond the {n_sub} sub-nodes the node counts")
        return found

    # -- CGNS on top of ADF: the sizes VTK allocates by ----------------------------------------------------------
    def values(self, node: _Node) -> bytes:
        """The data of a small node (its chunks lie inside the file: checked by ``data``)."""
        return b"".join(self.file.at(at, count) for at, count in node.spans)

    def integers(self, node: _Node) -> list[int] | None:
        """The values of a small I4 or I8 node; None for other types or more than 64 values."""
        if node.dtype not in (b"I4", b"I8") or prod(node.dims) > 64:
            return None
        size = self.sizes["int" if node.dtype == b"I4" else "long"]
        raw = self.values(node)
        return [int.from_bytes(raw[i:i + size], self.order, signed=True)
                for i in range(0, prod(node.dims) * size, size)]

    def sizes_of_zones(self) -> None:
        """Each base gives cell and physical dimensions of 1 to 3; each zone gives its sizes as 1 to 3 rows of
        vertex, cell and boundary-vertex counts, vertices at least 1 each way, a structured zone one cell fewer than
        vertices each way (as many ways as its base's cell dimension), and each coordinate array under its
        GridCoordinates (without rind planes) holds one value per vertex. VTK allocates a zone's points and cells by
        these sizes, and crashes or runs out of memory when they lie."""
        below: dict[str, list[_Node]] = defaultdict(list)
        for node in self.nodes.values():
            below[node.parent].append(node)
        for node in self.nodes.values():
            if node.label == b"CGNSBase_t":
                dims = self.integers(node)
                if dims is None or len(dims) != 2 or not 1 <= dims[0] <= dims[1] <= 3:
                    self.damaged(f"{self.where(node.path)} does not give a cell and a physical dimension of 1 to 3")
            elif node.label == b"Zone_t":
                self.zone(node, below)

    def zone(self, zone: _Node, below: dict[str, list[_Node]]) -> None:
        where = f"zone '{zone.path}'"
        sizes = self.integers(zone)
        if sizes is None or len(zone.dims) != 2 or zone.dims[1] != 3 or not 1 <= zone.dims[0] <= 3:
            self.damaged(f"{where} does not give its sizes as 1 to 3 rows of 3 integers")
        n = zone.dims[0]
        vertices, cells = sizes[:n], sizes[n:2 * n]
        if min(vertices) < 1 or min(sizes) < 0:
            self.damaged(f"{where} gives a size below 1 vertex (or a negative count)")
        kind = next((self.values(k) for k in below[zone.path] if k.label == b"ZoneType_t"), b"").rstrip(b" \0")
        base = self.nodes.get(zone.parent)
        if kind == b"Structured":
            cell_dim = (self.integers(base) or [n])[0] if base is not None and base.label == b"CGNSBase_t" else n
            if n != cell_dim or cells != [v - 1 for v in vertices]:
                self.damaged(f"{where} is a structured zone of {' x '.join(map(str, vertices))} vertices and "
                             f"{' x '.join(map(str, cells))} cells in a base of cell dimension {cell_dim}; a "
                             "structured zone has as many index dimensions as its base's cells and one cell fewer than "
                             "vertices each way")
        count = prod(vertices)
        for grid in below[zone.path]:
            if grid.label != b"GridCoordinates_t" or any(k.label == b"Rind_t" for k in below[grid.path]):
                continue
            for coord in below[grid.path]:
                if coord.label == b"DataArray_t" and coord.dims and prod(coord.dims) != count:
                    self.damaged(f"{self.where(coord.path)} holds {prod(coord.dims)} coordinates, but {where} gives "
                                 f"{count} vertices ({' x '.join(map(str, vertices))})")


def check_adf(path: PathLike) -> None:
    """Walk the ADF structure of the CGNS file ``path`` (see the module docstring); ReadError at the first
    inconsistency, None when the file header and every node, sub-node table and data chunk agree."""
    p = check_file(path)
    try:
        file = _File(p, p.stat().st_size)
    except OSError as exc:
        raise ReadError(p, f"could not be read ({exc.strerror or type(exc).__name__})") from None
    try:
        walk = _Walk(p, file)
        walk.tree(walk.header())
        walk.sizes_of_zones()
    finally:
        file.close()
