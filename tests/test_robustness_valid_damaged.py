"""The campaign's "valid as damaged" judgment (``volviz.bench.robustness_agree``, issue #32): the EnSight case file
of the campaign's seed cut right after its GEOMETRY section (byte 52 of 100, six cases of seed 33) is a valid case
without variables, and VTK's own reader reads it to the content volviz reads, so it is no silent acceptance; the same
reads of a file that lost data, a changed field, or a format VTK has no reader of stay garbage. Both sides are the
campaign's real worker reads (volviz in-process here, VTK's vtkGenericEnSightReader)."""
from __future__ import annotations

import pytest

from volviz.bench import robustness as rb
from volviz.bench.robustness_agree import same_content, valid_as_damaged
from volviz.bench.robustness_formats import _ensight


@pytest.fixture
def case(tmp_path, monkeypatch):
    monkeypatch.setenv("VOLVIZ_ISOLATE", "0")
    _ensight(tmp_path)
    path = tmp_path / "mesh.case"
    text = path.read_bytes()
    assert text[:52] == b"FORMAT\ntype: ensight gold\n\nGEOMETRY\nmodel: mesh.geo\n" and len(text) == 100
    return path, text


def _both(path):
    return {"volviz": rb._serve_volviz({"path": str(path), "options": {}}),
            "vtk": rb._serve_vtk({"path": str(path), "options": {}, "recipe": "ensight"})}


def test_a_case_file_cut_after_its_geometry_is_valid_as_damaged(case):
    path, text = case
    whole = _both(path)
    assert [f["n"] for f in whole["volviz"]["content"]] == [8]
    assert same_content(whole["volviz"]["content"], whole["vtk"]["content"])        # the sides agree on the seed
    assert whole["volviz"]["content"][0]["arrays"] == [[8.0, 14.0, 0.0, 3.5, 0.0]]  # temp: 8 values, sum 14
    path.write_bytes(text[:52])
    cut = _both(path)
    assert cut["volviz"]["content"] == [{"n": 8, "bounds": [0.0, 1.0, 0.0, 2.0, 0.0, 0.5], "arrays": []}]
    mutation = rb.truncate(text, 52)
    original = {side: answer for side, answer in whole.items()}
    assert rb._judge(cut["volviz"], original["volviz"], mutation, "ensight") == "garbage"  # its own judgment
    assert valid_as_damaged("truncate", cut)


def test_reads_that_differ_a_changed_field_or_no_second_reader_stay_garbage(case):
    path, text = case
    path.write_bytes(text[:52])
    cut = _both(path)
    path.write_bytes(text)
    whole = _both(path)
    assert not valid_as_damaged("truncate", {"volviz": cut["volviz"], "vtk": whole["vtk"]})   # variables differ
    assert not valid_as_damaged("field", cut)            # both following a changed header is no proof of validity
    assert not valid_as_damaged("truncate", {"volviz": cut["volviz"]})                        # no VTK reader
    warned = {**cut, "volviz": {**cut["volviz"], "warned": "a doubt the reader stated"}}
    assert not valid_as_damaged("truncate", warned)


def test_the_report_has_the_column(case):
    result = {"stats": {"ensight|volviz": {"cases": 3, "clean": 1, "valid": 2},
                        "ensight|vtk": {"cases": 3, "clean": 1, "valid": 2}},
              "slowest": {}, "contained": {}, "p99": {}, "slowest_case": {}, "examples": {}, "retimed": [],
              "cases": 3, "planned": 3, "seed": 1, "seconds": 1.0, "files": 1}
    text = rb.report(result, "volviz bench robustness --cases 3")
    assert "| garbage | valid | warned |" in text
    assert "| ensight | 3 | 1 \\| 1 | 0 \\| 0 | 0 \\| 0 | 0 \\| 0 | 0 \\| 0 | 0 \\| 0 | 2 \\| 2 | 0 \\| 0 |" in text
    assert "silent garbage: 0 — met (besides, valid as damaged: 2," in text


def test_replay_says_a_recorded_cut_case_file_is_valid_as_damaged(tmp_path):
    """``--replay`` of the campaign's case (recorded as the campaign records it) reads it on both sides now."""
    from volviz.bench.robustness_replay import Recorder, case_record

    src = next(s for s in rb.made_sources(tmp_path / "made", ["ensight"]) if s.name.endswith("mesh.case"))
    raw = src.path.read_bytes()
    mutation = rb.make_mutation(src, raw, ("truncate", 52))
    record = tmp_path / "cases.jsonl"
    recorder = Recorder(record)
    recorder.write({**case_record(56, 33, src, "made", ("truncate", 52), mutation, raw, mutation.data),
                    "outcome": {"volviz": "garbage", "vtk": "garbage"}})
    recorder.close()
    lines = rb.replay(record, 56, tmp_path / "data", tmp_path / "replay")
    assert lines[2:] == ["recorded outcome: volviz garbage, vtk garbage", "volviz now: read",
                         "VTK's reader now: ok, the same content: valid as damaged"]
