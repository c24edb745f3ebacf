"""Every case of ``volviz bench robustness`` reproducible (issue #32): a short campaign writes its record, and each
recorded case rebuilt by ``--replay`` is byte for byte the file the campaign read (its SHA-256), and the bytes and
bits the record lists, applied to the seed file, make that same file."""
from __future__ import annotations

import json

import pytest

from volviz.bench import robustness as rb
from volviz.bench import robustness_replay as rr

#: a text header (BOV), a binary one (MATLAB, written with a timestamp the bench pins) and HDF5 edited through h5py
FORMATS = ["bov", "matlab", "hdf5"]


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    base = tmp_path_factory.mktemp("campaign")
    (base / "data").mkdir()
    record = base / "cases.jsonl"
    result = rb.run(base / "data", 15, 7, FORMATS, progress=False, record=record)
    items = [json.loads(line) for line in record.read_text().splitlines()]
    return base, result, items


def _apply(original: bytes, item: dict) -> bytes:
    """The damaged file from the record's own description of the change."""
    out = original
    for run in reversed(item["runs"]):
        assert run["length_after"] <= rr.MAX_RUN_BYTES
        assert original[run["offset"]:run["offset"] + run["length_before"]].hex().startswith(run["before"])
        out = out[:run["offset"]] + bytes.fromhex(run["after"]) + out[run["offset"] + run["length_before"]:]
    return out


def test_every_case_is_recorded_with_its_outcome(campaign):
    _base, result, items = campaign
    assert [i["case"] for i in items] == list(range(result["cases"])) and result["cases"] == 15
    assert {i["format"] for i in items} == set(FORMATS)
    for item in items:
        assert item["seed"] == 7 and item["origin"] == "made" and item["outcome"]["volviz"] in rb.OUTCOMES
        assert len(item["sha256"]) == 64 and item["size_before"] > 0


def test_each_recorded_case_rebuilds_byte_identical(campaign, tmp_path):
    base, _result, items = campaign
    kinds = set()
    for item in items:
        target, opened, src = rb.rebuild(item, base / "data", tmp_path / "replay")
        damaged = target.read_bytes()
        assert rr.sha256(damaged) == item["sha256"] and opened.exists()
        original = src.path.read_bytes()
        assert rr.sha256(original) == item["source_sha256"]
        if item["kind"] != "hdf5-field" and item["runs_not_shown"] == 0:
            assert _apply(original, item) == damaged, item["case"]
        if item["kind"] == "bitflip":
            assert item["bits"] and all(original[o] ^ damaged[o] == 1 << b for o, b in item["bits"])
        kinds.add(item["kind"])
    assert {"truncate", "bitflip", "hdf5-field"} <= kinds, kinds


def test_a_case_whose_bytes_differ_from_the_record_is_refused(campaign, tmp_path):
    base, _result, items = campaign
    item = dict(items[0], sha256="0" * 64)
    with pytest.raises(rr.ReplayError, match="is not the recorded file"):
        rb.rebuild(item, base / "data", tmp_path)
    with pytest.raises(rr.ReplayError, match="no case 99 in the record"):
        rr.load(base / "cases.jsonl", 99)


def test_replay_command_rebuilds_and_reads_the_case(campaign, tmp_path, capsys):
    base, _result, items = campaign
    item = next(i for i in items if i["outcome"]["volviz"] == "clean")
    code = rb.main(["--data", str(base / "data"), "--record", str(base / "cases.jsonl"), "--replay",
                    str(item["case"]), "--into", str(tmp_path)])
    out = capsys.readouterr().out.splitlines()
    assert code == 0
    assert out[0].startswith(f"case {item['case']}: {item['format']} `{item['file']}` {item['kind']}")
    assert "as recorded" in out[1] and out[2] == "recorded outcome: volviz clean"
    assert out[3].startswith(f"volviz now: error: {tmp_path}/s{item['case']}/")


def test_a_case_is_placed_as_a_new_file_while_a_reader_holds_the_last_one(tmp_path):
    """A reader child may still hold the previous case of an HDF5 file open (and locked); the next case is written
    as a new file, which h5py can edit (the retiming of the re-run stopped on 'unable to lock file')."""
    import subprocess
    import sys

    import h5py
    import numpy as np

    target = tmp_path / "case.h5"
    with h5py.File(target, "w") as f:
        f["x"] = np.arange(3)
    raw = target.read_bytes()
    holder = subprocess.Popen([sys.executable, "-c", "import h5py, sys; f = h5py.File(sys.argv[1], 'r'); "
                               "print('open', flush=True); sys.stdin.read()", str(target)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "open\n"
        rb.place(target, raw)
        with h5py.File(target, "r+") as f:
            f["x"][0] = 7
        with h5py.File(target, "r") as f:
            assert list(f["x"][:]) == [7, 1, 2]
    finally:
        holder.stdin.close()
        holder.wait()


def test_the_laz_seeds_carry_a_pinned_date_so_they_rebuild_any_day(tmp_path):
    """laspy stamps a LAS header with today's date (day of year and year, bytes 90-93): the seed-33 campaign's LAZ
    cases, written on 2026-11-28, could not be rebuilt the next day ("the seed file ... is not the recorded one")."""
    import struct

    from volviz.bench.robustness_formats import SEEDS

    for seed in [s for s in SEEDS if s.fmt == "laz"]:
        folder = tmp_path / seed.label
        folder.mkdir()
        seed.write(folder)
        assert struct.unpack("<HH", (folder / "cloud.laz").read_bytes()[90:94]) == (1, 2026)
