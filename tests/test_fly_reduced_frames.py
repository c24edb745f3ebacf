"""While a fly-mode key is held, the viewport's frames are drawn at half its size in each direction and magnified to it
by the widget's blit (``volviz_app.reduced_frames``, issue #28: the natural scene while flying shows
reduced-resolution frames); between paints the render window keeps the viewport's size (what the views' requests
and read-backs see); after the release the frames stay reduced until the full-size views are shown, then the
full-resolution frame is drawn, and it is ``volviz render``'s picture."""
from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QEvent, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QApplication

from flows import assert_matches_render, wait_loaded, wait_settled


def _w(widget, kind: QEvent.Type, repeat: bool) -> None:
    QApplication.sendEvent(widget, QKeyEvent(kind, Qt.Key.Key_W, Qt.KeyboardModifier.NoModifier, "w", repeat))


def test_frames_while_flying_are_drawn_at_half_size(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_demo()      # terrain, fog, clouds and sky
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    window.action_fly.trigger()
    canvas, ren_win, frames = window.plotter.interactor, window.plotter.ren_win, window.fly.frames
    full = tuple(ren_win.GetSize())
    half = ((full[0] + 1) // 2, (full[1] + 1) // 2)
    renders: list[tuple[tuple[int, int], bool]] = []     # (size, drawn in a paint) of each render
    observer = ren_win.AddObserver("EndEvent", lambda *a: renders.append((tuple(ren_win.GetSize()),
                                                                          bool(canvas._in_paint))))
    between: set[tuple[int, int]] = set()
    _w(canvas, QEvent.Type.KeyPress, False)
    for _ in range(40):
        qtbot.wait(33)
        between.add(tuple(ren_win.GetSize()))             # between paints: the viewport's size
        _w(canvas, QEvent.Type.KeyPress, True)
    qtbot.waitUntil(lambda: frames.renders >= 3, timeout=60000)
    _w(canvas, QEvent.Type.KeyRelease, False)
    flown = list(renders)
    assert between == {full}
    assert frames.active and frames.last_size == half
    painted = [size for size, in_paint in flown if in_paint]
    assert len(painted) >= 3 and set(painted) == {half}   # every frame drawn while flying: a quarter of the pixels
    wait_settled(qtbot, window, timeout=180000)
    qtbot.waitUntil(lambda: window.controller.nature.shown_scale == 1 and not frames.active, timeout=180000)
    qtbot.waitUntil(lambda: renders[-1] == (full, True), timeout=10000)   # then the full-resolution frame
    ren_win.RemoveObserver(observer)
    assert tuple(ren_win.GetSize()) == full
    assert_matches_render(window, tmp_path)


def test_a_flight_resumed_before_the_full_size_views_keeps_reduced_frames(qtbot, make_window) -> None:
    """The end of the reduced frames asked for at a stop (``ReducedFrames.ending``) is void once a new step started:
    a key pressed while the full-size views are still being made keeps the frames reduced; fly mode off ends them."""
    window = make_window()
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    window.action_fly.trigger()
    frames = window.fly.frames
    _w(window.plotter.interactor, QEvent.Type.KeyPress, False)
    assert frames.active
    end = frames.ending()          # the stop's views are being made ...
    _w(window.plotter.interactor, QEvent.Type.KeyPress, True)      # ... when the user flies on
    end()
    assert frames.active
    frames.ending()()
    assert not frames.active
    _w(window.plotter.interactor, QEvent.Type.KeyPress, True)
    assert frames.active
    window.action_fly.trigger()    # fly mode off
    assert not window.fly.enabled and not frames.active
