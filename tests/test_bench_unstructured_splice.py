"""``volviz bench unstructured --only``: the rows it runs replace their own blocks of the existing report (the sort
table with its index buffer line, the large mesh with its paragraphs) and keep every other line."""
from __future__ import annotations

import pytest

from volviz.bench.unstructured import LARGE_HEAD, SORT_HEAD, main, splice

REPORT = "\n".join([
    "# Report", "", "Command: `full run`", "",
    f"{SORT_HEAD} (old):", "", "| sort | 256x256 |", "|---|---|", "| mpvo | 0.1 |", "",
    f"{LARGE_HEAD} old numbers.", "", "Drawn at 256² old draw.", "",
    "Speed-up of pt over the fastest VTK mapper in this run: **1.04x** (target ≥ 5x).", ""])


def test_blocks_are_replaced_and_the_rest_kept():
    note = "(The rows below come from a run of their own, spliced into this report: `cmd`.)"
    out = splice(REPORT, SORT_HEAD, ["", note, "", f"{SORT_HEAD} (new):", "", "| sort | 512x512 |", "|---|---|",
                                     "| mpvo | 0.01 |", "", "The order as the GPU pass's index buffer: 1 ms."])
    out = splice(out, LARGE_HEAD, [note, "", f"{LARGE_HEAD} new numbers.", "", "Drawn at 256² new draw."])
    assert out.split("\n") == [
        "# Report", "", "Command: `full run`", "",
        note, "", f"{SORT_HEAD} (new):", "", "| sort | 512x512 |", "|---|---|", "| mpvo | 0.01 |", "",
        "The order as the GPU pass's index buffer: 1 ms.", "",
        note, "", f"{LARGE_HEAD} new numbers.", "", "Drawn at 256² new draw.", "",
        "Speed-up of pt over the fastest VTK mapper in this run: **1.04x** (target ≥ 5x).", ""]
    # spliced again, each block (with its run note) is replaced once more, not stacked
    again = splice(out, SORT_HEAD, [note, "", f"{SORT_HEAD} (newer):", "", "| mpvo | 0.02 |"])
    assert again.count(note) == 2 and "(new):" not in again and "| mpvo | 0.02 |" in again
    assert again.count(LARGE_HEAD) == 1 and again.endswith("(target ≥ 5x).\n")


def test_a_missing_block_goes_before_the_speed_up_line():
    text = "# Report\n\nSpeed-up of pt: 1x.\n"
    assert splice(text, LARGE_HEAD, ["", f"{LARGE_HEAD} n."]) == f"# Report\n\n{LARGE_HEAD} n.\n\nSpeed-up of pt: 1x.\n"


def test_only_refuses_unknown_rows_and_a_large_row_without_a_refinement():
    from volviz.argtypes import UsageError

    with pytest.raises(UsageError, match=r"argument --only: unknown row 'raster' \(known: sort, large, cpu, exact\)"):
        main(["--only", "sort,raster"])
    with pytest.raises(UsageError, match="--only large needs --large-refine > 1"):
        main(["--only", "large"])


def test_each_block_keeps_one_run_note_when_several_are_spliced_in_turn():
    """``--only sort,cpu`` on a report whose blocks each start with a run note: each block's note is replaced, the
    next block's note is left to it (the run note was taken for the CPU block's ratio line, which came last among
    the block tails: the sort and CPU blocks got two notes each and the large block lost its own)."""
    from volviz.bench.unstructured import CPU_HEAD, RUN_NOTE

    def note(what: str) -> str:
        return f"{RUN_NOTE} of their own, spliced into this report: `{what}`.)"

    report = "\n".join([
        "# Report", "",
        note("cpu old"), "", f"{CPU_HEAD} (old):", "", "| window | s |", "|---|---|", "| 64x64 | 1 |", "",
        "The CPU side against its cost at 512²: 1.00x.", "",
        note("sort old"), "", f"{SORT_HEAD} (old):", "", "| mpvo | 0.1 |", "",
        "The order as the GPU pass's index buffer: 1 ms.", "",
        note("large old"), "", f"{LARGE_HEAD} old numbers.", "", "Drawn at 256² old draw.", "",
        "Speed-up of pt over the fastest VTK mapper in this run: **1.04x** (target ≥ 5x).", ""])
    out = splice(report, SORT_HEAD, [note("sort new"), "", f"{SORT_HEAD} (new):", "", "| mpvo | 0.01 |", "",
                                     "The order as the GPU pass's index buffer: 2 ms."])
    out = splice(out, CPU_HEAD, [note("cpu new"), "", f"{CPU_HEAD} (new):", "", "| 64x64 | 2 |", "",
                                 "The CPU side against its cost at 512²: 0.99x."])
    assert out.split("\n") == [
        "# Report", "",
        note("cpu new"), "", f"{CPU_HEAD} (new):", "", "| 64x64 | 2 |", "",
        "The CPU side against its cost at 512²: 0.99x.", "",
        note("sort new"), "", f"{SORT_HEAD} (new):", "", "| mpvo | 0.01 |", "",
        "The order as the GPU pass's index buffer: 2 ms.", "",
        note("large old"), "", f"{LARGE_HEAD} old numbers.", "", "Drawn at 256² old draw.", "",
        "Speed-up of pt over the fastest VTK mapper in this run: **1.04x** (target ≥ 5x).", ""]
