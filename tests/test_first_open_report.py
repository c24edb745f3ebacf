"""docs/first-open.md has two generators, each owning its own section between markers (issue #30): the app's window
table (volviz_app.first_open) and `volviz bench first_open`'s render table; regenerating one keeps the other and the
prose around them. And the bench measures a picture (PPM, JPEG: no transfer function) without an error in its row."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from volviz.bench import first_open as bench
from volviz.io.doc_section import SectionError, read_section, write_section
from volviz_app import first_open as app_first_open

REPORT = Path(__file__).resolve().parents[1] / "docs" / "first-open.md"


def test_a_section_is_appended_then_replaced_alone(tmp_path):
    doc = tmp_path / "report.md"
    write_section(doc, "<!-- a: begin -->", "<!-- a: end -->", "first A\n")
    assert doc.read_text() == "<!-- a: begin -->\n\nfirst A\n\n<!-- a: end -->\n"
    doc.write_text(doc.read_text() + "\nprose between\n")
    write_section(doc, "<!-- b: begin -->", "<!-- b: end -->", "B")
    doc.write_text(doc.read_text() + "\nprose after\n")
    write_section(doc, "<!-- a: begin -->", "<!-- a: end -->", "second A")
    assert doc.read_text() == ("<!-- a: begin -->\n\nsecond A\n\n<!-- a: end -->\n\nprose between\n\n"
                               "<!-- b: begin -->\n\nB\n\n<!-- b: end -->\n\nprose after\n")
    assert read_section(doc, "<!-- b: begin -->", "<!-- b: end -->") == "B"
    assert read_section(tmp_path / "absent.md", "<!-- b: begin -->", "<!-- b: end -->") == ""


@pytest.mark.parametrize("text", ["x\n<!-- a: begin -->\ny\n", "<!-- a: end -->\n<!-- a: begin -->\n"])
def test_broken_markers_are_refused_naming_the_file(tmp_path, text):
    doc = tmp_path / "report.md"
    doc.write_text(text)
    with pytest.raises(SectionError, match=r"report\.md: the section markers .* are broken"):
        write_section(doc, "<!-- a: begin -->", "<!-- a: end -->", "new")
    assert doc.read_text() == text


def _split(text: str, begin: str, end: str) -> tuple[str, str, str]:
    a, b = text.index(begin), text.index(end) + len(end)
    return text[:a], text[a:b], text[b:]


def test_the_app_table_and_the_bench_table_keep_each_other(tmp_path):
    doc = tmp_path / "first-open.md"
    doc.write_text(REPORT.read_text())
    original = doc.read_text()

    records = [app_first_open.FirstOpen(Path("x"), "volumes/neghip.slc", "slc", "volume (VTK)", "66 x 66 x 66",
                                        "SLCImage", 0.8, "volumes__neghip.slc.png")]
    app_first_open.write_table(doc, records, "first-open")
    after_app = doc.read_text()
    before, section, rest = _split(after_app, app_first_open.BEGIN, app_first_open.END)
    assert before + rest == "".join(_split(original, app_first_open.BEGIN, app_first_open.END)[::2])
    rows = [line for line in section.splitlines() if line.startswith("| `")]
    assert rows == ["| `volumes/neghip.slc` | slc | volume (VTK) | 66 x 66 x 66 | SLCImage | 0.8 s | "
                    "[png](first-open/volumes__neghip.slc.png) |  |"]
    assert bench.BEGIN in rest and "Before the background-mode placement" in rest   # the bench's section, the prose

    clouds = bench.FirstImage("sky/clouds.jpeg", 0.1, 1.5, 0.39, "picture", cpu=1.21, slowest=1.9)
    bench.write_section(bench.markdown([clouds], {}), doc)
    before, section, rest = _split(doc.read_text(), bench.BEGIN, bench.END)
    assert before + rest == "".join(_split(after_app, bench.BEGIN, bench.END)[::2])
    assert "| `sky/clouds.jpeg` | 0.1 | picture | 1.5 s | 1.9 s | 1.21 s | 39% |  |  |  |  |" in section.splitlines()


def test_an_only_run_of_the_app_rewrites_its_rows_and_keeps_the_others(tmp_path):
    doc = tmp_path / "first-open.md"
    doc.write_text(REPORT.read_text())
    kept = app_first_open._kept_rows(doc)
    assert "volumes/neghip.slc" in kept and "volumes/embryo.slc" in kept
    fresh = app_first_open.FirstOpen(Path("x"), "volumes/neghip.slc", "slc", "volume (PT)", "66 x 66 x 66",
                                     "SLCImage", 9.9, "volumes__neghip.slc.png")
    order = list(kept)
    app_first_open.write_table(doc, [fresh], "first-open", order)
    rows = app_first_open._kept_rows(doc)
    assert list(rows) == order
    assert "| volume (PT) |" in rows["volumes/neghip.slc"] and "| 9.9 s |" in rows["volumes/neghip.slc"]
    assert all(rows[n] == kept[n] for n in order if n != "volumes/neghip.slc")


def test_the_bench_measures_a_picture_without_an_error(tmp_path):
    """A colour PPM has no transfer function: the row says "picture", its time and drawn share, and no error (it
    said AttributeError: 'NoneType' object has no attribute 'range')."""
    rng = np.random.default_rng(3)
    pixels = rng.integers(0, 256, size=(48, 64, 3), dtype=np.uint8)
    (tmp_path / "photo.ppm").write_bytes(b"P6\n64 48\n255\n" + pixels.tobytes())
    [record] = bench.measure(tmp_path)
    assert record.note == ""
    assert record.kind == "picture"
    assert record.visible is None and record.contrast is None
    assert record.seconds is not None and record.drawn is not None and record.drawn > 0.02


def test_an_only_run_of_the_bench_keeps_the_other_rows_and_the_profiles(tmp_path):
    doc = tmp_path / "first-open.md"
    doc.write_text(REPORT.read_text())
    old = read_section(doc, bench.BEGIN, bench.END)
    kept = [line for line in old.splitlines() if line.startswith("| `")]
    order = [line.split("`")[1] for line in kept]
    assert "sky/clouds.jpeg" in order and len(order) > 20
    clouds = bench.FirstImage("sky/clouds.jpeg", 0.1, 1.5, 0.39, "picture", cpu=1.21, slowest=1.9)
    fresh = bench.markdown([clouds], {})
    bench.write_section(bench.kept_rows(fresh, False, order, report=doc), doc)
    new = read_section(doc, bench.BEGIN, bench.END)
    rows = [line for line in new.splitlines() if line.startswith("| `")]
    assert [line.split("`")[1] for line in rows] == order
    assert rows[order.index("sky/clouds.jpeg")] == ("| `sky/clouds.jpeg` | 0.1 | picture | 1.5 s | 1.9 s | 1.21 s "
                                                    "| 39% |  |  |  |  |")
    assert all(a == b for a, b in zip(rows, kept) if "sky/clouds.jpeg" not in a)
    assert new[new.index(bench.PROFILE_HEAD):] == old[old.index(bench.PROFILE_HEAD):]
