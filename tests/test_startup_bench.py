"""``volviz bench startup`` (issue #30): ``--files`` times ``volviz render FILE`` of every file ``volviz bench
first_open`` opens; a file volviz refuses is a row saying so (its one-line error), not a crash of the benchmark;
each row carries the load at its case's start."""
from __future__ import annotations

import sys

from conftest import data_file

from volviz.bench.first_open import opened_files
from volviz.bench.startup import Result, file_cases, measure, report


def test_file_cases_are_every_opened_file() -> None:
    data = data_file("volumes/hydrogen.vti").parents[1]
    cases = file_cases(data)
    assert len(cases) == len(opened_files(data)) and len(cases) > 20       # every file is under 100 MB
    by_name = {name: argv for name, argv, display in cases}
    assert by_name["render bluntfin/bluntfinxyz.bin"] == [
        "-m", "volviz.cli", "render", str(data / "bluntfin" / "bluntfinxyz.bin"), "-o", "{tmp}/f.png"]
    assert "render ecosystem/openfoam-cavity" in by_name                    # a case folder opened whole
    assert not any(display for _, _, display in cases)


def test_a_refused_file_is_a_row(tmp_path) -> None:
    missing = tmp_path / "missing.vti"
    argv = [sys.executable, "-m", "volviz.cli", "render", str(missing), "-o", str(tmp_path / "x.png")]
    (result,) = measure("render missing.vti", argv, reps=2, first_frame=False, trees=[""], extras=False)
    assert result.walls == [] and result.cpus == []
    assert result.refused == (f"volviz: error: {missing}: no such file (give a session, a data file, 'demo' or "
                              "'demo-volume')")
    timed = Result("render x.vti", walls=[1.0, 3.0, 2.0], cpus=[0.5, 0.7, 0.6], load=2.5)
    text = report([result, timed], "volviz bench startup --files", ("1.0, 1.0, 1.0", "2.0, 2.0, 2.0"))
    rows = [line for line in text.splitlines() if line.startswith("| render")]
    assert rows == [f"| render missing.vti | this checkout | {result.load:.1f} | refused: {result.refused} | | | |",
                    "| render x.vti | this checkout | 2.5 | 2.00 s (1.00-3.00) | 0.60 s |  |  |"]
    assert "Largest imports" not in text
