"""An AVS UCD file whose header line is cut short (issue #32, the campaigns' AVS UCD cut at byte 33 or 35 of the
bench's hexahedron, rebuilt with ``volviz bench robustness --replay``): with fewer than five counts it was no longer
sniffed as AVS UCD, and meshio's Abaqus reader, the other reader of ``.inp``, read it as an empty or other mesh.
Any line of counts after the comments is now sniffed as AVS UCD, whose check names the short header line, when the
complete lines after it fit its counts (node lines, cell lines, a data section's counts: three of four of them, or a
cell line among them) or there are none."""
from __future__ import annotations

import pytest

import volviz.io as vio
from volviz.bench.robustness_formats import SEEDS
from volviz.io.registry import spec_of
from volviz_vtk_readers.specs import is_avs_ucd


@pytest.fixture
def mesh(tmp_path):
    seed = next(s for s in SEEDS if s.fmt == "avs-ucd" and s.label == "hexahedron")
    seed.write(tmp_path)
    path = tmp_path / "mesh.inp"
    assert path.read_bytes().startswith(b"# Written by meshio v5.3.5\n8 1 1 1 0\n")
    return path


def test_the_seed_reads_as_written(mesh):
    assert spec_of(mesh).name == "avs-ucd" and vio.read(mesh).n_points == 8


@pytest.mark.parametrize("cut, counts", [(33, "8 1 1"), (35, "8 1 1 1")])
def test_a_header_line_cut_short_is_refused_as_avs_ucd(mesh, cut, counts):
    mesh.write_bytes(mesh.read_bytes()[:cut])
    assert spec_of(mesh).name == "avs-ucd"
    with pytest.raises(vio.ReadError, match=rf"^{mesh}: line 2 \('{counts}'\) is not the header line \(five counts: "
                                            r"nodes, cells, node values, cell values, model values\)$"):
        vio.read(mesh)


@pytest.mark.parametrize("header, message", [
    (b"9 1 1 1 0", r"line 11 \('1 0 hex 5 6 8 7 1 2 4 3'\) is not node 9 of 9 \(4 numbers\)"),
    (b"2147483647 1 1 1 0", r"line 11 \('1 0 hex 5 6 8 7 1 2 4 3'\) is not node 9 of 2147483647 \(4 numbers\)"),
    (b"0 1 1 1 0", r"line 3 \('1 0.0 0.0 0.0'\) is not cell 1 of 1 \(id, material, type and its nodes\)"),
    (b"8 9 1 1 0", r"line 12 \('1 1'\) is not cell 2 of 9 \(id, material, type and its nodes\)"),
    (b"8 0 1 1 0", r"line 11 \('1 0 hex 5 6 8 7 1 2 4 3'\) is not the node data's components line"),
])
def test_a_damaged_count_leaves_the_file_avs_ucd_refused_by_line(mesh, header, message):
    """The sniffer holds the lines after the header against its counts (a point table starting with whole numbers
    is no AVS UCD, tests/test_robustness_xyz_sniffing.py); a count that no longer fits them leaves most of them
    fitting, or a cell line there, so the file stays AVS UCD and its check names the line (meshio's Abaqus reader,
    the other reader of .inp, reads these as 0 points)."""
    mesh.write_bytes(mesh.read_bytes().replace(b"8 1 1 1 0", header))
    assert is_avs_ucd(mesh.read_bytes()) and spec_of(mesh).name == "avs-ucd"
    with pytest.raises(vio.ReadError, match=f"^{mesh}: {message}"):
        vio.read(mesh, isolate=False)


@pytest.mark.parametrize("cut", [40, 60, 140])
def test_a_file_cut_in_its_node_lines_stays_avs_ucd(mesh, cut):
    """The cut last line (no line end) is not held against the counts; the complete node lines before it fit."""
    mesh.write_bytes(mesh.read_bytes()[:cut])
    assert is_avs_ucd(mesh.read_bytes()) and spec_of(mesh).name == "avs-ucd"
    with pytest.raises(vio.ReadError, match=rf"^{mesh}: line \d+ \('[^']*'\) is not node \d of 8 \(4 numbers\)"):
        vio.read(mesh, isolate=False)
