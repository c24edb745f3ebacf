"""Transfer-function edits made with the mouse, undone and redone from the keyboard (issue #28, found driving the app as
a new user): on X11 Qt's standard redo key is only Ctrl+Shift+Z, so Ctrl+Y (the redo key on Windows) did nothing
while Edit > Redo was enabled. Each undo must give back the earlier picture exactly, each redo the later one."""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtWidgets import QApplication

from flows import _mouse, assert_matches_render, click, drag, open_settled, pick_combo_item, screen, wait_settled


def _points(canvas) -> list[QPoint]:
    """Where the TF editor's control points are drawn."""
    return [canvas.to_screen(float(s), float(r)).toPoint() for s, r in zip(canvas.scalars, canvas.extinction)]


def _key(qtbot, window, key: Qt.Key) -> None:
    """Ctrl+``key`` pressed as the user does: to the focused widget of the active window."""
    qtbot.keyClick(QApplication.focusWidget() or window, key, Qt.KeyboardModifier.ControlModifier)
    wait_settled(qtbot, window)


def test_mouse_edits_of_the_tf_undo_and_redo_from_the_keyboard_to_the_same_pictures(qtbot, make_window,
                                                                                    tmp_path) -> None:
    """ironProt.vtk in a 1280x740 window: a control point dragged up, one added by a click, one removed by a right
    click, a color preset picked: four edits, four different pictures. Ctrl+Z four times gives back each earlier
    picture exactly, down to the first; Ctrl+Y four times each later one, up to the last, which matches ``volviz
    render`` of the saved session."""
    window = open_settled(qtbot, make_window, "volumes/ironProt.vtk")
    canvas = window.tf_editor.canvas
    window.tf_dock.raise_()
    shots = [screen(window)]
    points = _points(canvas)
    drag(qtbot, canvas, points[len(points) // 2], points[len(points) // 2] + QPoint(0, -30))
    wait_settled(qtbot, window)
    shots.append(screen(window))
    click(qtbot, canvas, QPoint(int(canvas.width() * 0.3), int(canvas.height() * 0.25)))
    wait_settled(qtbot, window)
    shots.append(screen(window))
    second = QPointF(_points(canvas)[1])
    right = Qt.MouseButton.RightButton
    _mouse(canvas, QEvent.Type.MouseButtonPress, second, right, right)
    _mouse(canvas, QEvent.Type.MouseButtonRelease, second, Qt.MouseButton.NoButton, right)
    wait_settled(qtbot, window)
    shots.append(screen(window))
    pick_combo_item(qtbot, window.tf_editor.presets, "hot")
    wait_settled(qtbot, window)
    shots.append(screen(window))
    assert window.tf_editor.undo_stack.count() == 4
    for earlier, later in zip(shots, shots[1:]):
        assert not np.array_equal(later, earlier)          # each edit changed the picture

    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    for k in range(3, -1, -1):
        _key(qtbot, window, Qt.Key.Key_Z)
        assert np.array_equal(screen(window), shots[k]), f"undo to edit {k}"
    for k in range(1, 5):
        _key(qtbot, window, Qt.Key.Key_Y)
        assert window.tf_editor.undo_stack.index() == k    # before the fix: Ctrl+Y did nothing (index 0)
        assert np.array_equal(screen(window), shots[k]), f"redo to edit {k}"
    assert_matches_render(window, tmp_path, "redone", max_rmse=1.0, max_off=0.002)
