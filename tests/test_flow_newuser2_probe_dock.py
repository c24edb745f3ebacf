"""Pinning a probed value keeps the transfer-function dock whole (issue #28, found driving the app as a new user at
1280x740): the Probe dock, shown at the first pin below the right-hand column's tabbed docks, took 250 pixels of the
column's height from the transfer-function dock, whose Undo, Redo, Import and Export buttons and its info line then
lay out of view. It now comes up as a tab of the Scene dock's group, in front."""
from __future__ import annotations

from PySide6.QtCore import QPoint

from flows import assert_matches_render, click, hover, open_settled, wait_settled


def _whole(widget) -> bool:
    """``widget`` is painted whole on screen (none of it clipped by a scroll area or another dock)."""
    return widget.isVisible() and widget.visibleRegion().boundingRect() == widget.rect()


def test_a_pinned_probe_leaves_the_tf_dock_whole(qtbot, make_window, tmp_path) -> None:
    """disk_out_ref.ex2 (an Exodus mesh drawn as a PT volume) in a 1280x740 window: the TF dock's buttons and info
    line are whole; a click at the viewport's centre pins the value there: the Probe dock is in front and lists it,
    the TF dock's buttons and info line are still whole and its height unchanged, and the viewport (its size too)
    matches ``volviz render`` of the saved session."""
    window = open_settled(qtbot, make_window, "ecosystem/disk_out_ref.ex2")
    editor = window.tf_editor
    controls = [editor.undo_button, editor.redo_button, editor.import_button, editor.export_button, editor.info]
    assert all(_whole(w) for w in controls)
    tf_height, viewport = window.tf_dock.height(), tuple(window.plotter.window_size)

    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    hover(qtbot, canvas, centre)
    qtbot.waitUntil(lambda: window.probe.label.text().startswith("Probe: data: value"), timeout=10000)
    click(qtbot, canvas, centre)
    probe = window.probe
    qtbot.waitUntil(lambda: probe.pinned.count() == 1 and probe.dock.isVisible())
    qtbot.wait(200)                                   # the docks laid out again
    assert probe.pinned.item(0).text() == probe.last.text()
    assert not probe.pinned.visibleRegion().isEmpty()            # the pinned list is in front
    hidden = [w.text() for w in controls if not _whole(w)]
    assert hidden == [], hidden                       # before the fix: all five out of view
    assert window.tf_dock.height() == tf_height
    assert tuple(window.plotter.window_size) == viewport
    wait_settled(qtbot, window)
    assert_matches_render(window, tmp_path, "pinned", max_rmse=1.0, max_off=0.002)
