"""Keyboard-only use: Tab walks through the docks and the focused control is always one the user sees (issue #28,
found driving the app as a new user at 1024x600 and 1280x740). Qt keeps the docks behind a tab in the Tab chain, so
from the Scene dock's opacity slider Tab went on through the unseen Render settings, Statistics, Clipping, Slices and
Isosurfaces controls: 25 presses with nothing on screen showing where the keys went, an arrow key there changing the
renderer or the export size unseen."""
from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication, QDockWidget

from flows import open_settled


def _dock_of(widget) -> QDockWidget | None:
    while widget is not None and not isinstance(widget, QDockWidget):
        widget = widget.parentWidget()
    return widget


def test_tab_through_the_window_shows_each_focused_control(qtbot, make_window) -> None:
    """sqnz_s.adf.cgns in a 1280x740 window, the viewport focused: Tab pressed until the focus is back in the
    viewport; after each press the focused control is painted somewhere on screen (a non-empty visible region), and
    every tabbed dock (Render settings, Statistics, Clipping, Slices, Isosurfaces) was brought to the front on the
    way; Shift+Tab back into the Scene dock brings it to the front again."""
    window = open_settled(qtbot, make_window, "ecosystem/sqnz_s.adf.cgns")
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    viewport = window.plotter.interactor
    viewport.setFocus()
    unseen, fronted = [], set()
    for _ in range(80):
        qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_Tab)
        focused = QApplication.focusWidget()
        if focused is viewport:
            break
        dock = _dock_of(focused)
        if focused.visibleRegion().isEmpty():
            unseen.append((type(focused).__name__, dock.windowTitle() if dock else None))
        elif dock is not None:
            fronted.add(dock.windowTitle())
    else:
        raise AssertionError("Tab never came back to the viewport")
    assert unseen == [], unseen        # before the fix: 25 controls of the docks behind the Scene tab
    tabbed = {d.windowTitle() for d in window.tabifiedDockWidgets(window.scene_dock)} | {"Scene"}
    assert tabbed <= fronted, tabbed - fronted
    qtbot.keyClick(viewport, Qt.Key.Key_Backtab)   # back to the Scene dock's last control
    focused = QApplication.focusWidget()
    assert _dock_of(focused) is window.scene_dock and not focused.visibleRegion().isEmpty()
