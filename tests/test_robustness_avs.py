"""An AVS UCD file whose header line is cut short (issue #32, the campaigns' AVS UCD cut at byte 33 or 35 of the
bench's hexahedron, rebuilt with ``volviz bench robustness --replay``): with fewer than five counts it was no longer
sniffed as AVS UCD, and meshio's Abaqus reader, the other reader of ``.inp``, read it as an empty or other mesh.
Any line of counts after the comments is now sniffed as AVS UCD, whose check names the short header line."""
from __future__ import annotations

import pytest

import volviz.io as vio
from volviz.bench.robustness_formats import SEEDS
from volviz.io.registry import spec_of


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
