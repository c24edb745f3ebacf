"""Fly mode knows a movement key is held from its press to the user's release (issue #28, fly stalls): a frame that
keeps the GUI thread busy past the settle time (``FLY_SETTLE_MS``) while W is held is not the end of the flight.
Before, the settle timer fired in the middle of a loaded flight: the still rate and a full-size frame with a
synchronous render (255-326 ms each, 5 times in a 20-s flight at load 7), which delayed the next repeat further."""
from __future__ import annotations

import time

from PySide6.QtCore import QEvent, Qt
from PySide6.QtGui import QFocusEvent, QKeyEvent
from PySide6.QtWidgets import QApplication

from conftest import data_file
from flows import wait_loaded, wait_settled
from volviz_app.view_scheduler import FLY_SETTLE_MS


def _w(widget, kind: QEvent.Type, repeat: bool) -> None:
    QApplication.sendEvent(widget, QKeyEvent(kind, Qt.Key.Key_W, Qt.KeyboardModifier.NoModifier, "w", repeat))


def test_a_long_frame_while_w_is_held_is_not_the_end_of_the_flight(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    window.action_fly.trigger()
    canvas = window.plotter.interactor
    rate = window.plotter.ren_win.GetDesiredUpdateRate
    _w(canvas, QEvent.Type.KeyPress, False)
    for _ in range(3):                      # X11's auto-repeat: a release and a press, both marked as repeats
        qtbot.wait(33)
        _w(canvas, QEvent.Type.KeyRelease, True)
        _w(canvas, QEvent.Type.KeyPress, True)
    assert window.fly.held and rate() > 1   # flying, at the interactive rate
    time.sleep(2 * FLY_SETTLE_MS / 1000)    # a long frame: the GUI thread busy past the settle time
    qtbot.wait(100)                         # the overdue settle timer fires
    assert window.fly.held and rate() > 1   # still flying
    _w(canvas, QEvent.Type.KeyPress, True)
    _w(canvas, QEvent.Type.KeyRelease, False)   # the user lets go
    assert not window.fly.held
    qtbot.waitUntil(lambda: rate() < 1, timeout=5000)   # the flight ends: the still rate
    assert window.fly.steps == 5
    _w(canvas, QEvent.Type.KeyPress, False)
    QApplication.sendEvent(canvas, QFocusEvent(QEvent.Type.FocusOut))   # released in another window: no release here
    assert not window.fly.held
