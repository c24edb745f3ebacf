"""``volviz bench iso_modes_volume`` (issue #28): two modes on neghip at a small size write a report of the three
ways each, named by what drew them (the GPU passes as before; the CPU overlay without the volume split; for 3-pass the
split drawn on the GUI thread as before; now: the overlay with the split off the GUI thread for 3-pass, the GPU's
surfaces peeled with the volume for exact)."""
from __future__ import annotations

from conftest import data_file
from volviz.bench import iso_modes_volume as bench


def test_report_names_its_command_and_what_drew_each_way(tmp_path, capsys) -> None:
    neghip = data_file("volumes/neghip.slc")
    out = tmp_path / "report.md"
    argv = ["--data", str(neghip.parents[1]), "--modes", "3pass", "exact", "--sizes", "64x48", "--reps", "1",
            "--out", str(out)]
    assert bench.main(argv) == 0
    text = out.read_text()
    assert f"Command: `volviz bench iso_modes_volume {' '.join(argv)}`" in text
    rows = [[cell.strip() for cell in line.split("|")[1:-1]] for line in text.splitlines()
            if line.startswith("| neghip.slc | 64x48 |")]
    assert [(r[2], r[3]) for r in rows] == [
        ("3pass", "GPU passes (before)"), ("3pass", "CPU overlay, unsplit (before)"),
        ("3pass", "CPU overlay, volume split on the GUI thread (before)"),
        ("3pass", "now: CPU overlay, volume split off the GUI thread"),
        ("exact", "GPU passes (before)"), ("exact", "CPU overlay, unsplit (before)"),
        ("exact", "now: GPU, peeled with the volume")]
    assert all(float(r[4]) > 0 for r in rows)                           # ms per frame
    # a begin and a GUI-thread part: the CPU overlay's, the latter including the former
    assert [r[5] != "" for r in rows] == [r[6] != "" for r in rows] == [False, True, True, True, False, True, False]
    assert all(r[5].isdigit() and r[6].isdigit() and int(r[6]) >= int(r[5]) for r in rows if r[5])
    assert "wrote" in capsys.readouterr().out
