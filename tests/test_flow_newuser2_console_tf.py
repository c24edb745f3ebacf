"""A transfer function set from the Python console is the one the TF dock shows and edits (issue #28, found driving
the app as a new user): the view followed ``session.set_transfer_function`` typed in the console, but the dock kept
the previous function, so the next drag of a control point put the previous colors back and the script's edit was
lost."""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QApplication

from flows import assert_matches_render, drag, open_settled, screen, wait_settled
from test_flow_console import _run


def test_a_console_edit_of_the_tf_is_kept_by_the_next_drag_in_the_dock(qtbot, make_window, tmp_path) -> None:
    """HeadMRVolume.mhd; in View > Python Console the 'hot' preset is set as the volume's transfer function over its
    range: the dock shows it (its points and colors); a control point is then dragged up in the dock: the volume keeps
    the hot colors with the new opacity (the session's function is the hot one with one point moved), the screen
    matches ``volviz render`` of the saved session; Ctrl+Z twice gives back the first picture exactly."""
    from volviz.optics.presets import load_preset

    window = open_settled(qtbot, make_window, "volumes/HeadMRVolume.mhd")
    window.python_console.action.trigger()
    console = window.python_console
    qtbot.waitUntil(lambda: console.widget is not None and console.widget.isVisible(), timeout=30000)
    wait_settled(qtbot, window)
    first = screen(window)
    comp = window.session.components[0].id
    lo, hi = window.session.transfer_function(comp).range
    _run(qtbot, console, "from volviz.optics.presets import load_preset; c = session.components[0].id; "
         "session.set_transfer_function(c, load_preset('hot').rescaled(*session.transfer_function(c).range)); "
         "print('SET')", "SET\n")
    wait_settled(qtbot, window)
    hot = load_preset("hot").rescaled(lo, hi)
    editor = window.tf_editor
    assert np.array_equal(editor.canvas.scalars, hot.scalars)          # before the fix: the previous function
    assert np.array_equal(editor.canvas.colors, hot.colors)
    scripted = screen(window)
    assert not np.array_equal(scripted, first)

    window.tf_dock.raise_()
    canvas = editor.canvas
    i = len(hot.scalars) // 2
    start = canvas.to_screen(float(hot.scalars[i]), float(hot.extinction[i])).toPoint()
    drag(qtbot, canvas, start, start + QPoint(0, -25))
    wait_settled(qtbot, window)
    shown = window.session.transfer_function(comp)
    assert np.array_equal(shown.colors, hot.colors)      # the script's colors kept (before: the previous ones)
    assert np.array_equal(np.delete(shown.extinction, i), np.delete(hot.extinction, i))
    assert shown.extinction[i] > hot.extinction[i]
    assert_matches_render(window, tmp_path, "dragged", max_rmse=1.0, max_off=0.002)

    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    window.plotter.interactor.setFocus()
    for _ in range(2):
        qtbot.keyClick(QApplication.focusWidget() or window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
        wait_settled(qtbot, window)
    assert np.array_equal(screen(window), first)
