"""The fast slice of ``volviz bench robustness`` for the formats its first campaign left out (issue #32): XDMF,
Tecplot, EnSight, AVS UCD, OME-Zarr, MINC, HDF5 arrays, CSV points, .xyz, BOV, PVD, LAZ and ``.vvz``
(``volviz.bench.robustness_formats``: seeds written by the formats' own libraries, every file of a seed of several
files damaged in turn). Each format's seeds meet a truncation at a header boundary and random mutations of the
kinds that fit each file (bit flips, header fields, XML attributes, HDF5 metadata, JSON values, ``.vvz`` metadata
and brick records with their checksums recomputed), read as the bench reads them; property: the original's size
with consistent arrays (the original's values when only truncated), a ReadWarning naming the file, or a ReadError
naming it -- never another exception. VTK's reader of each format that has one reads every seed intact."""
from __future__ import annotations

import random

import pytest

from volviz.bench import robustness as rb
from volviz.bench.robustness_formats import FORMATS, SEEDS

MUTATIONS = 3           # per damaged file of a seed, after one truncation
#: formats whose reader (a plugin's, VTK's underneath) still reads a truncated file as other data without a word:
#: found by the new-format campaign (docs/reliability.md), open; strict, so that the fix must remove the mark
OPEN: dict[str, str] = {}


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    return rb.made_sources(tmp_path_factory.mktemp("seeds"), FORMATS)


def _case(src: rb.Source, folder, mutation: rb.Mutation | None) -> dict:
    """Place the (mutated) file among its seed's other files and read it as the bench's volviz side does."""
    target = rb.mutated_path(src, folder)
    data = src.path.read_bytes()
    rb.place(target, data if mutation is None or mutation.data is None else mutation.data)
    if mutation is not None and mutation.edit is not None:
        mutation.edit(target)
    return rb._serve_volviz({"path": str(folder / src.target), "options": src.options})


def test_every_format_has_several_seeds_or_files():
    for fmt in FORMATS:
        seeds = [s for s in SEEDS if s.fmt == fmt]
        assert len(seeds) >= 2 or len(seeds[0].mutate) >= 2, fmt


@pytest.mark.parametrize("fmt", [pytest.param(f, marks=pytest.mark.xfail(strict=True, reason=OPEN[f])) if f in OPEN
                                 else f for f in FORMATS])
def test_damaged_files_read_consistently_or_are_refused_naming_the_file(seeds, fmt, tmp_path):
    sources = [s for s in seeds if s.fmt == fmt]
    if not sources:
        pytest.skip(f"the library that writes {fmt} is not installed")
    outcomes = []
    for k, src in enumerate(sources):
        folder = rb.prepare_folder(src, tmp_path, k)
        original = _case(src, folder, None)
        assert original["status"] == "ok" and original["problem"] == "" and not original["warned"], original
        data = src.path.read_bytes()
        rng = random.Random(f"{fmt}:{k}")
        cases = [rb.truncate(data, rng.choice(rb.boundaries(src, data)))]
        cases += [rb.random_mutation(src, data, rng, rb.hdf5_object_addresses(src.path)
                                     if src.layout == "hdf5" else None) for _ in range(MUTATIONS)]
        for mutation in cases:
            answer = _case(src, folder, mutation)
            outcome = rb._judge(answer, original, mutation, fmt)
            assert outcome in ("clean", "warned", "accepted"), (src.name, mutation.detail, outcome, answer)
            if answer["status"] == "error":
                assert answer["message"].startswith(str(folder)), answer["message"]
            outcomes.append(outcome)
    assert set(outcomes) - {"accepted"}, outcomes  # the damage reaches the reader's checks


@pytest.mark.parametrize("seed", [s for s in SEEDS if s.vtk], ids=lambda s: f"{s.fmt}-{s.label}")
def test_vtk_reads_each_seed_it_has_a_reader_for(seed, tmp_path):
    try:
        seed.write(tmp_path)
    except ImportError:
        pytest.skip(f"the library that writes {seed.fmt} is not installed")
    from vtkmodules.vtkCommonCore import vtkOutputWindow

    window = vtkOutputWindow.GetInstance()          # the bench's VTK side takes VTK's messages; given back after
    try:
        answer = rb._serve_vtk({"path": str(tmp_path / seed.target), "options": {}, "recipe": seed.vtk})
    finally:
        vtkOutputWindow.SetInstance(window)
    assert answer["status"] == "ok" and answer["n_points"] > 0, answer
