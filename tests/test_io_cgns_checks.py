"""The structure checks of CGNS files made before VTK's vtkCGNSReader sees them: ADF files walked node by node
(``volviz_vtk_readers.adf``), CGNS/HDF5 files visited with h5py (``volviz_vtk_readers.cgnshdf5``).

Damaged copies of the shared ADF sample (``ecosystem/sqnz_s.adf.cgns``, ADF version A: pointers and dimensions in
ASCII hexadecimal) are written to tmp_path and read through ``volviz.io.read``; each must be refused with a ReadError
that names the file and comes from the check (``CGNS ADF:``), not from VTK failing on it. The valid file, and a copy
rewritten in ADF version B (binary pointers and dimensions, what the CGNS library writes today), must pass and read
as before.
"""
from __future__ import annotations

import random
import re
import struct
from pathlib import Path

import numpy as np
import pytest

import volviz.io as vio
from conftest import data_file
from volviz.bench import robustness as rb
from volviz_vtk_readers.adf import check_adf
from volviz_vtk_readers.cgnshdf5 import check_cgns_hdf5

SAMPLE = "ecosystem/sqnz_s.adf.cgns"
POINTS, CELLS = 15228, 11264
# offsets in a 246-byte ADF node header
NAME, LABEL, N_SUB, SUB_TABLE, DTYPE, N_DIMS, DIMS, N_CHUNKS, DATA = 4, 36, 68, 84, 96, 128, 130, 226, 230


@pytest.fixture(scope="module")
def sample() -> bytes:
    return data_file(SAMPLE).read_bytes()


def node_at(data: bytes, name: str) -> int:
    """Where the header of the (first) node called ``name`` starts."""
    at = data.find(b"NoDe" + name.encode().ljust(32))
    assert at > 0, name
    return at


def pointer(data: bytes, at: int) -> int:
    """The byte an ASCII-hex disk pointer (version A) addresses."""
    return int(data[at:at + 8], 16) * 4096 + int(data[at + 8:at + 12], 16)


def hex_pointer(address: int) -> bytes:
    return b"%08X%04X" % divmod(address, 4096)


def patched(data: bytes, at: int, new: bytes) -> bytes:
    return data[:at] + new + data[at + len(new):]


def refused(tmp_path: Path, data: bytes, problem: str) -> str:
    """Read ``data`` as a .cgns file: it must be refused by the check with a message naming the file and matching
    ``problem``; the message."""
    path = tmp_path / "damaged.cgns"
    path.write_bytes(data)
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    message = str(info.value)
    assert message.startswith(f"{path}: CGNS ADF: "), message
    assert re.search(problem, message), message
    return message


# -------------------------------------------------------------------------------------------------- valid files
def test_valid_file_passes_and_reads_as_before(sample, tmp_path):
    check_adf(data_file(SAMPLE))
    copy = tmp_path / "copy.cgns"
    copy.write_bytes(sample)
    mesh = vio.read(copy)
    assert mesh.n_points == POINTS and mesh.n_cells == CELLS
    assert set(mesh.cell_data) == {"Density", "Momentum", "EnergyStagnationDensity"}


def to_version_b(data: bytes) -> bytes:
    """The version A sample rewritten as the CGNS library writes ADF today (version B02012): every disk pointer as an
    8-byte block and a 4-byte offset, every node's twelve dimensions as 8-byte integers, in the file's byte order
    (little-endian, 'L'); the numeric data is left as it is."""
    out = bytearray(patched(data, 25, b"B02012>"))

    def binary(at: int) -> None:
        block, offset = divmod(pointer(data, at), 4096)
        out[at:at + 12] = struct.pack("<QI", block, offset)

    for at in (134, 146, 158, 170, *range(190, 262, 12)):  # file header and free-chunk table
        binary(at)
    stack = [pointer(data, 134)]
    while stack:
        node = stack.pop()
        dims = [int(data[node + DIMS + 8 * i:node + DIMS + 8 * i + 8], 16) for i in range(12)]
        out[node + DIMS:node + DIMS + 96] = struct.pack("<12Q", *dims)
        table, n_sub = pointer(data, node + SUB_TABLE), int(data[node + N_SUB:node + N_SUB + 8], 16)
        entries = int(data[node + 76:node + 84], 16)
        if int(data[node + N_CHUNKS:node + N_CHUNKS + 4], 16) == 1:
            binary(pointer(data, node + DATA) + 4)  # the data chunk's end pointer
        if entries:
            binary(table + 4)
            for i in range(entries):
                binary(table + 16 + 44 * i + 32)
            stack += [pointer(data, table + 16 + 44 * i + 32) for i in range(n_sub)]
        binary(node + SUB_TABLE)
        binary(node + DATA)
    return bytes(out)


def test_version_b_file_passes_and_reads_the_same(sample, tmp_path):
    path = tmp_path / "version_b.cgns"
    path.write_bytes(to_version_b(sample))
    check_adf(path)
    original, rewritten = vio.read(data_file(SAMPLE)), vio.read(path)
    assert rewritten.n_points == original.n_points == POINTS
    np.testing.assert_array_equal(rewritten.points, original.points)
    np.testing.assert_array_equal(rewritten.cell_data["Density"], original.cell_data["Density"])


# ------------------------------------------------------------------------------------------------ damaged files
@pytest.mark.parametrize("where", ["file header", "free-chunk table", "root node", "first child", "sub-node table",
                                   "a zone's coordinates", "last end tag"])
def test_truncated_at_a_node_boundary(sample, tmp_path, where):
    grid = node_at(sample, "GridCoordinates")
    cut = {"file header": 186, "free-chunk table": 266, "root node": 512, "first child": 758,
           "sub-node table": pointer(sample, 266 + SUB_TABLE) + 16 + 2 * 44, "a zone's coordinates": grid + 246,
           "last end tag": pointer(sample, 146)}[where]
    refused(tmp_path, sample[:cut], r"shorter than its header|the file holds \d+ bytes.*the file is truncated")


@pytest.mark.parametrize("name,offset,tag", [("CoordinateX", 0, b"NoDx"), ("CoordinateX", 242, b"Tail"),
                                             ("dom1_1_1_1", 0, b"\0\0\0\0"), ("ADF MotherNode", 242, b"TAIL")])
def test_node_tag_damaged(sample, tmp_path, name, offset, tag):
    refused(tmp_path, patched(sample, node_at(sample, name) + offset, tag), "lacks its NoDe/TaiL boundary tags")


def test_chunk_and_table_tags_damaged(sample, tmp_path):
    coord = node_at(sample, "CoordinateX")
    chunk = pointer(sample, coord + DATA)
    refused(tmp_path, patched(sample, chunk, b"DaTx"), "data chunk of node '.*CoordinateX' .*lacks its DaTa start tag")
    refused(tmp_path, patched(sample, pointer(sample, chunk + 4), b"dEnd"), "lacks its dEnD end tag")
    table = pointer(sample, 266 + SUB_TABLE)
    refused(tmp_path, patched(sample, table, b"SNTB"), "sub-node table of the root node .*lacks its SNTb start tag")
    refused(tmp_path, patched(sample, pointer(sample, table + 4), b"snTe"), "lacks its snTE end tag")
    refused(tmp_path, patched(sample, 64, b"Adf1"), "file header lacks its AdF1 boundary tag at byte 64")


@pytest.mark.parametrize("value,problem", [
    (b"7FFFFFFF", r"claims 1391569403256 bytes \(1.4 TB\) of data \(2147483647 x 9 x 9 values of 8 bytes \(R8\)\), "
                  r"but the whole file holds 1003520 bytes"),
    (b"FFFFFFFF", r"claims 2783138807160 bytes \(2.8 TB\) of data"),  # -1 as a 32-bit count
    (b"-0000001", r"dimension 1 of node '.*CoordinateX' .*is not a hexadecimal number"),
    (b"00000000", "has a dimension of 0"),
    (b"00000012", r"claims 11664 bytes of data \(18 x 9 x 9 .*\), but its data chunks hold 9720 bytes"),
])
def test_dimension_damaged(sample, tmp_path, value, problem):
    coord = node_at(sample, "CoordinateX")
    dims = [int(sample[coord + DIMS + 8 * i:coord + DIMS + 8 * i + 8], 16) for i in range(3)]
    assert dims == [15, 9, 9]
    refused(tmp_path, patched(sample, coord + DIMS, value), problem)


def test_dimension_count_and_unused_dimension_damaged(sample, tmp_path):
    coord = node_at(sample, "CoordinateX")
    refused(tmp_path, patched(sample, coord + N_DIMS, b"0D"), "has 13 dimensions; ADF allows 12 at most")
    refused(tmp_path, patched(sample, coord + N_DIMS, b"04"), "a value in an unused dimension field|dimension of 0")
    refused(tmp_path, patched(sample, 266 + DIMS + 3 * 8, b"00\x7f\xff\xff\xff00"),
            r"dimension 4 of the root node \(byte 266\) is not a hexadecimal number")
    refused(tmp_path, patched(sample, 266 + DIMS + 3 * 8, b"00000001"), "a value in an unused dimension field")


def test_data_chunk_address_past_the_end(sample, tmp_path):
    coord = node_at(sample, "CoordinateX")
    refused(tmp_path, patched(sample, coord + DATA, hex_pointer(len(sample) + 4096)),
            r"data chunk of node '.*CoordinateX' \(byte \d+\) at byte \d+ reaches past the end of the file \(1003520 "
            r"bytes\)")
    refused(tmp_path, patched(sample, coord + DATA, b"00000000F000"), "gives an offset of 61440 in a 4096-byte block")
    chunk = pointer(sample, coord + DATA)  # the chunk's own end pointer, past the end
    refused(tmp_path, patched(sample, chunk + 4, hex_pointer(len(sample) + 8)), "end tag of the data chunk .*reaches "
                                                                                "past the end of the file")
    refused(tmp_path, patched(sample, coord + N_CHUNKS, b"0000"), "declares 9720 bytes of data .* but stores none")


@pytest.mark.parametrize("dtype,problem", [(b"R9", "has a data type ADF does not know"),
                                           (b"X8", r"claims 19440 bytes of data .*\(X8\)\), but its data chunks hold "
                                                   "9720 bytes"),
                                           (b"MT", r"has no data type \(MT\) but 3 dimensions and 1 data chunks")])
def test_data_type_changed(sample, tmp_path, dtype, problem):
    refused(tmp_path, patched(sample, node_at(sample, "CoordinateX") + DTYPE, dtype), problem)


def test_sub_node_count_enlarged_or_reduced(sample, tmp_path):
    # the root lists 2 children in a table of 8 entries; its third entry is unused (a blank pointer)
    refused(tmp_path, patched(sample, 266 + N_SUB, b"00000003"),
            r"header of node 'unused entry in sub-node-table' at byte 4096 .*lacks its NoDe/TaiL|lacks its NoDe/TaiL")
    refused(tmp_path, patched(sample, 266 + N_SUB, b"00000009"), "counts 9 sub-nodes but its sub-node table has room "
                                                                 "for 8")
    refused(tmp_path, patched(sample, 266 + N_SUB, b"00000001"), "lists a node in entry 2, beyond the 1 sub-nodes")
    refused(tmp_path, patched(sample, 266 + 76, b"00000009"), "holds 352 bytes, not the 9 entries")


def test_cycle_back_to_the_root_or_to_the_node_itself(sample, tmp_path):
    zone = node_at(sample, "dom1_1_1_1")
    table = pointer(sample, zone + SUB_TABLE)
    first_child = table + 16 + 32  # the pointer of the zone's first sub-node table entry
    name = sample[table + 16:table + 48]
    root_named = patched(patched(sample, first_child, hex_pointer(266)), 266 + NAME, name)  # names agree
    refused(tmp_path, root_named, "already in the tree \\(a cycle\\)")
    itself = patched(patched(sample, first_child, hex_pointer(zone)), table + 16, b"dom1_1_1_1".ljust(32))
    refused(tmp_path, itself, r"sub-node table of node 'SQNZ/dom1_1_1_1' lists the node at byte \d+, which is already "
                              r"in the tree \(a cycle\)")


def test_child_pointing_elsewhere_or_renamed(sample, tmp_path):
    zone = node_at(sample, "dom1_1_1_1")
    first_child = pointer(sample, zone + SUB_TABLE) + 16 + 32
    refused(tmp_path, patched(sample, first_child, hex_pointer(node_at(sample, "CoordinateY"))),
            "gives another name in its header than in the sub-node table of node 'SQNZ/dom1_1_1_1'")
    coord = node_at(sample, "CoordinateX")
    refused(tmp_path, patched(sample, coord + NAME, b"CoordinateW"), "gives another name in its header")


@pytest.mark.parametrize("label,problem", [(b"Zonu_t", "one or two bits away from CGNS's Zone_t"),
                                           (b"Zone_t\x01", "has a label that is not text"),
                                           (b"DataArray_u", "one or two bits away from CGNS's DataArray_t")])
def test_label_damaged(sample, tmp_path, label, problem):
    name = "dom1_2_1_1" if label.startswith(b"Zon") else "CoordinateZ"
    refused(tmp_path, patched(sample, node_at(sample, name) + LABEL, label.ljust(32)), problem)


@pytest.mark.parametrize("value,problem", [
    (-1, "gives a size below 1 vertex"), (0, "gives a size below 1 vertex"),
    (2**31 - 1, "is a structured zone of 2147483647 x 9 x 9 vertices and 16 x 8 x 8 cells"),
    (18, "is a structured zone of 18 x 9 x 9 vertices")])
def test_zone_size_damaged(sample, tmp_path, value, problem):
    zone = node_at(sample, "dom1_3_2_2")
    values = pointer(sample, zone + DATA) + 16
    assert struct.unpack("<9i", sample[values:values + 36]) == (17, 9, 9, 16, 8, 8, 0, 0, 0)
    refused(tmp_path, patched(sample, values, struct.pack("<i", value)), f"zone 'SQNZ/dom1_3_2_2' {problem}")
    both = patched(sample, values, struct.pack("<4i", 18, 9, 9, 17))  # cells agree, coordinates do not
    refused(tmp_path, both, r"node 'SQNZ/dom1_3_2_2/GridCoordinates/Coordinate.' holds 1377 coordinates, but zone "
                            r"'SQNZ/dom1_3_2_2' gives 1458 vertices")


def test_base_dimensions_damaged(sample, tmp_path):
    base = pointer(sample, node_at(sample, "SQNZ") + DATA) + 16
    assert struct.unpack("<2i", sample[base:base + 8]) == (3, 3)
    refused(tmp_path, patched(sample, base, struct.pack("<i", 4)), "node 'SQNZ' does not give a cell and a physical "
                                                                   "dimension of 1 to 3")


def test_header_fields_damaged(sample, tmp_path):
    refused(tmp_path, patched(sample, 146, hex_pointer(len(sample) + 100)), "data reach byte 1003620, but the file "
                                                                            "holds 1003520 bytes")
    refused(tmp_path, patched(sample, 134, b"0000000Z010A"), "root-node pointer is not a hexadecimal number")
    refused(tmp_path, patched(sample, 110, b"00"), r"gives sizeof\(int\) = 0, not 4 or 8")
    refused(tmp_path, patched(sample, 25, b"C"), "an ADF version other than A or B")
    refused(tmp_path, patched(sample, 100, b"X"), "numeric format ADF does not know")
    refused(tmp_path, patched(sample, 186, b"fcbt"), "free-chunk table at byte 186 lacks its fCbt/Fcte tags")


def test_version_b_damaged(sample, tmp_path):
    b = to_version_b(sample)
    coord = node_at(b, "CoordinateX")
    refused(tmp_path, patched(b, coord + DIMS, struct.pack("<Q", 2**31 - 1)),
            r"claims 1391569403256 bytes \(1.4 TB\) of data")
    refused(tmp_path, patched(b, coord + DIMS, struct.pack("<q", -1)),
            r"claims \d+ bytes \(.* EB\) of data \(18446744073709551615 x 9 x 9")
    refused(tmp_path, patched(b, coord + DIMS + 8, struct.pack("<Q", 0)), "has a dimension of 0")
    refused(tmp_path, patched(b, coord + DATA, struct.pack("<QI", 10**6, 0)), "reaches past the end of the file")
    refused(tmp_path, patched(b, 100, b"N"), "numeric format ADF does not know")


def test_campaign_mutations_are_refused_or_read_unchanged(sample, tmp_path):
    """The fuzz campaign's mutations of the sample (``volviz bench robustness``): each is refused by the check, or
    (a change the structure cannot show: a date, a data bit, an unused entry's name) reads as the original."""
    src = next(s for s in rb.sources(data_file(SAMPLE).parent) if s.fmt == "cgns")
    rng = random.Random(5)
    mutations = rb.systematic(src, sample)[:40] + [rb.random_mutation(src, sample, rng) for _ in range(40)]
    accepted = 0
    for i, mutation in enumerate(mutations):
        path = tmp_path / f"case{i}.cgns"
        path.write_bytes(mutation.data)
        try:
            check_adf(path)
        except vio.ReadError as exc:
            assert str(path) in str(exc)
            continue
        accepted += 1
        mesh = vio.read(path)
        assert (mesh.n_points, mesh.n_cells) == (POINTS, CELLS), mutation.detail
    assert accepted < len(mutations) // 2


# --------------------------------------------------------------------------------------------------- CGNS/HDF5
def cgns_like_hdf5(path: Path, shape: tuple[int, ...]) -> Path:
    """A small HDF5 file laid out as CGNS/HDF5 (a group per node, its data in a `` data`` dataset), whose one data
    array has ``shape`` (allocated lazily, so the file stays small whatever it claims)."""
    import h5py

    with h5py.File(path, "w", libver="latest") as f:
        f.create_dataset(" format", data=np.frombuffer(b"IEEE_LITTLE_64", dtype=np.int8))
        zone = f.create_group("Base").create_group("Zone")
        zone.attrs["label"] = np.bytes_("Zone_t")
        grid = zone.create_group("GridCoordinates").create_group("CoordinateX")
        grid.create_dataset(" data", shape=shape, dtype="f8")
    return path


def test_hdf5_consistent_file_passes(tmp_path):
    check_cgns_hdf5(cgns_like_hdf5(tmp_path / "small.cgns", (17, 9, 9)))
    check_cgns_hdf5(data_file(SAMPLE))  # ADF: not this check's business


def test_hdf5_dataset_larger_than_the_file_is_refused(tmp_path):
    path = cgns_like_hdf5(tmp_path / "huge.cgns", (2**31 - 1, 9, 9))
    with pytest.raises(vio.ReadError, match=re.escape(str(path)) + r": CGNS/HDF5: dataset /Base/Zone/GridCoordinates/"
                       r"CoordinateX/ data claims 1391569403256 bytes, more than the file's \d+ bytes"):
        vio.read(path)


def test_hdf5_damaged_metadata_is_refused(tmp_path):
    path = cgns_like_hdf5(tmp_path / "damaged.cgns", (17, 9, 9))
    data = bytearray(path.read_bytes())
    headers = [m.start() for m in re.finditer(b"OHDR", data)]
    assert len(headers) >= 4
    at = headers[-1]  # the last object header: the data array's
    data[at + 6:at + 40] = bytes(34)
    path.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError, match=re.escape(str(path)) + ": CGNS/HDF5: the HDF5 library could not read "
                                                                    "the file's structure"):
        vio.read(path)
