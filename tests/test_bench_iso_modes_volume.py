"""``volviz bench iso_modes_volume`` (issue #28): one mode on neghip at a small size writes a report of the three
ways, each drawn by what it says (the GPU passes; the CPU overlay without and with the volume split)."""
from __future__ import annotations

from conftest import data_file
from volviz.bench import iso_modes_volume as bench


def test_report_names_its_command_and_the_three_ways(tmp_path, capsys) -> None:
    neghip = data_file("volumes/neghip.slc")
    out = tmp_path / "report.md"
    argv = ["--data", str(neghip.parents[1]), "--modes", "3pass", "--sizes", "64x48", "--reps", "1", "--out", str(out)]
    assert bench.main(argv) == 0
    text = out.read_text()
    assert f"Command: `volviz bench iso_modes_volume {' '.join(argv)}`" in text
    rows = [[cell.strip() for cell in line.split("|")[1:-1]] for line in text.splitlines()
            if line.startswith("| neghip.slc | 64x48 | 3pass |")]
    assert [r[3] for r in rows] == [label for label, _, _ in bench.WAYS]
    assert all(float(r[4]) > 0 for r in rows)                 # ms per frame
    assert rows[0][5] == "" and all(r[5].isdigit() for r in rows[1:])   # only the CPU overlay has a begin
    assert "wrote" in capsys.readouterr().out
