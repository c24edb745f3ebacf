"""The fast slice of ``volviz bench robustness`` for the formats the shared data lacks (issue #32): one small valid
file of each (``volviz.bench.robustness_made``: MATLAB plain and compressed, TIFF, NRRD raw and gzip, NIfTI, DICOM,
cube, FITS, MRC, .npy, LAS, SEG-Y), 12 mutations each (truncations at header boundaries, bit flips, header fields),
read through ``volviz.io.read`` as a user reads them. Property: a dataset of the original's size with consistent
arrays (and the original's values when the file was only truncated), or a ReadError naming the file -- never
another exception, never a crash of this process."""
from __future__ import annotations

import random

import pytest

import volviz.io as vio
from volviz.bench import robustness as rb
from volviz.bench.robustness_made import MADE

CASES = 12


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    folder = tmp_path_factory.mktemp("made")
    return {s.fmt: s for s in rb.made_sources(folder)}


@pytest.mark.parametrize("fmt", sorted(MADE))
def test_mutated_made_files_read_consistently_or_raise_read_error(made, fmt, tmp_path):
    if fmt not in made:
        pytest.skip(f"the library that writes {fmt} is not installed")
    src = made[fmt]
    data = src.path.read_bytes()
    original = rb.fingerprint_volviz(vio.read(src.path))
    assert original["problem"] == "" and original["n_points"] > 0
    rng = random.Random(fmt)
    cuts = rb.boundaries(src, data)
    mutations = [rb.truncate(data, at) for at in rng.sample(cuts, min(4, len(cuts)))]
    mutations += [rb.random_mutation(src, data, rng, kind=kind) for kind in ("bitflip", "field") * 4]
    target = tmp_path / src.path.name
    outcomes = []
    for mutation in mutations[:CASES]:
        target.write_bytes(mutation.data)
        try:
            found = rb.fingerprint_volviz(vio.read(target))
        except vio.ReadError as exc:
            assert str(exc).startswith(str(target)), f"{mutation.detail}: {exc}"
            outcomes.append("refused")
            continue
        assert found["problem"] == "", f"{mutation.detail}: {found['problem']}"
        assert found["n_points"] == original["n_points"], f"{mutation.detail}: size changed and was accepted"
        if mutation.kind == "truncate":
            assert found["crc"] == original["crc"], f"{mutation.detail}: a truncated file read with other data"
        outcomes.append("read")
    assert "refused" in outcomes  # at least the cut at byte 0
