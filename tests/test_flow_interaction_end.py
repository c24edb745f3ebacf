"""The end of a camera interaction in the real window (issue #28: no event-loop stall over 100 ms): a wheel notch or a
drag's release is drawn at VTK's interactive rate, and the still frame follows as a repaint once the interaction has
settled (``volviz_app.interaction_renders``; drawn in strips when slow). Before, VTK's style drew a whole still frame
inside the event's handler, then the repaint drew it again: for neghip at this size 150-330 ms on this machine.

``SPLIT_OVER_S`` is 0 here, so that the still frames are drawn in strips whatever this machine's speed."""
from __future__ import annotations

from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from flows import drag_viewport
from strip_flows import assert_strips_left_the_whole_frame, neghip_in_strips


def _renders(window) -> list[tuple[str, bool]]:
    """From now on, for each render of the window: 'strip' (a pass of a frame in strips) or 'whole', and whether it
    was at the still rate."""
    strips, ren_win = window.still_strips, window.plotter.ren_win
    still = window.plotter.iren.interactor.GetStillUpdateRate()
    seen: list[tuple[str, bool]] = []
    ren_win.AddObserver("StartEvent", lambda *args: seen.append(("strip" if strips._ours else "whole",
                                                                 ren_win.GetDesiredUpdateRate() <= still)))
    return seen


def _settled_frame_is_the_still_frame(qtbot, window, monkeypatch) -> None:
    strips = window.still_strips
    qtbot.waitUntil(lambda: strips.frames > 0 and not strips.drawing and not window.single_render.settle.isActive(),
                    timeout=30000)
    assert_strips_left_the_whole_frame(window, monkeypatch)


def test_a_wheel_notch_draws_nothing_in_its_handler_then_the_still_frame_in_strips(qtbot, make_window,
                                                                                    monkeypatch) -> None:
    window = neghip_in_strips(qtbot, make_window, monkeypatch)
    distance = window.plotter.camera.GetDistance()
    renders = _renders(window)
    frames = window.still_strips.frames
    canvas = window.plotter.interactor
    pos = QPointF(canvas.width() / 2, canvas.height() / 2)
    QApplication.sendEvent(canvas, QWheelEvent(pos, canvas.mapToGlobal(pos), QPoint(0, 0), QPoint(0, 120),
                                               Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier,
                                               Qt.ScrollPhase.NoScrollPhase, False))
    assert renders == [] and window.plotter.camera.GetDistance() < distance   # zoomed in, nothing drawn yet
    qtbot.waitUntil(lambda: window.still_strips.frames > frames and not window.still_strips.drawing, timeout=30000)
    assert renders[0] == ("whole", False), renders                  # the notch at the interactive rate
    assert ("whole", True) not in renders, renders                  # the still frame only in strips
    _settled_frame_is_the_still_frame(qtbot, window, monkeypatch)


def test_a_drags_release_draws_the_still_frame_only_in_strips(qtbot, make_window, monkeypatch) -> None:
    window = neghip_in_strips(qtbot, make_window, monkeypatch)
    renders = _renders(window)
    frames = window.still_strips.frames
    drag_viewport(qtbot, window, 120, 30)
    qtbot.waitUntil(lambda: window.still_strips.frames > frames and not window.still_strips.drawing, timeout=30000)
    assert ("whole", True) not in renders, renders
    assert ("strip", True) in renders
    _settled_frame_is_the_still_frame(qtbot, window, monkeypatch)
