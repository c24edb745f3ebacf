"""``volviz bench strips`` (issue #28): neghip at 320x240, drawn whole and in 4 strips, writes a report that
names its command, times each way and shows that the strips draw the whole frame's picture."""
from __future__ import annotations

from conftest import data_file
from volviz.bench import strips as bench


def test_report_names_its_command_and_the_strips_draw_the_whole_frame(tmp_path, capsys) -> None:
    neghip = data_file("volumes/neghip.slc")
    out = tmp_path / "strips.md"
    argv = ["--targets", str(neghip), "--sizes", "320x240", "--reps", "1", "--strips", "4", "--out", str(out)]
    assert bench.main(argv) == 0
    text = out.read_text()
    assert f"Command: `volviz bench strips {' '.join(argv)}`" in text
    rows = [[cell.strip() for cell in line.split("|")[1:-1]] for line in text.splitlines()
            if line.startswith(f"| {neghip} | 320x240 |")]
    assert len(rows) == 1
    whole, strips, passes, longest, last, total = (float(v) for v in rows[0][2:8])
    assert strips == 4 and passes == 5            # four strips and the pass of the scalar bar, title and axes
    assert whole > 0 and 0 < longest <= total and 0 < last <= longest
    rmse, off = float(rows[0][9]), float(rows[0][10].rstrip(" %"))
    # the same picture: measured RMSE 2.26, 0.15 % of the pixels off by more than 24 levels, on the outline's lines
    # over the volume (the ray caster stops at them in the depth it reads per strip) and at the volume's edge
    assert rmse < 3.0 and off < 0.5, rows[0]
    assert "wrote" in capsys.readouterr().out
