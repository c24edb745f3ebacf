"""A transfer-function point dragged over a regular volume: the frames of the drag at VTK's interactive rate, the
finished edit's at the still rate (issue #28, docs/bench/flow-gaps.md: each preview of the drag was a still frame,
its ray cast holding the event loop 150-330 ms at the window's size on this machine, where the interactive rate
takes 19-40 ms). The picture the user is left with is ``volviz render``'s."""
from __future__ import annotations

from PySide6.QtCore import QPoint

from flows import assert_matches_render, drag, open_settled, wait_settled


def test_a_tf_drag_previews_at_the_interactive_rate_and_ends_at_the_still_rate(qtbot, make_window, tmp_path) -> None:
    window = open_settled(qtbot, make_window, "volumes/neghip.slc")
    canvas = window.tf_editor.canvas
    window.tf_dock.raise_()
    qtbot.waitUntil(canvas.isVisible)
    ren_win = window.plotter.ren_win
    rates: list[float] = []
    tag = ren_win.AddObserver("StartEvent", lambda *args: rates.append(ren_win.GetDesiredUpdateRate()))
    point = canvas.to_screen(float(canvas.scalars[len(canvas.scalars) // 2]),
                             float(canvas.extinction[len(canvas.extinction) // 2])).toPoint()
    try:
        drag(qtbot, canvas, point, point + QPoint(0, -40), steps=10)
        wait_settled(qtbot, window)
    finally:
        ren_win.RemoveObserver(tag)
    assert window.tf_editor.undo_stack.count() == 1
    still = window.plotter.iren.interactor.GetStillUpdateRate()
    assert any(rate > 1.0 for rate in rates), rates          # the drag's previews (before: all at the still rate)
    assert rates[-1] == still and ren_win.GetDesiredUpdateRate() == still, rates   # the finished edit, and after it
    assert_matches_render(window, tmp_path, "tf-drag")
