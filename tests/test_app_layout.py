"""The window's layout under Xvfb: the viewport's share, the fit on a laptop screen, persistence between launches and
View > Reset Layout, tooltips on every control, and the Help menu's dialogs."""
from __future__ import annotations

import gc
from pathlib import Path

import pytest
from PySide6.QtCore import QPoint, QRect, QSettings, Qt
from PySide6.QtWidgets import (QAbstractButton, QAbstractItemView, QAbstractSlider, QAbstractSpinBox, QComboBox,
                               QPlainTextEdit, QScrollArea, QWidget)

from test_app_window import window  # noqa: F401  (the fixture)
from volviz_app.layout import DEFAULT_SIZE
from volviz_app.window import MainWindow

CONTROLS = (QAbstractButton, QAbstractItemView, QAbstractSlider, QAbstractSpinBox, QComboBox, QPlainTextEdit)


def settle(qtbot, window: MainWindow, size: tuple[int, int]) -> None:
    window.resize(*size)
    qtbot.waitUntil(lambda: window.size().toTuple() == size)
    qtbot.wait(50)  # the docks are laid out in the event loop


def rect_in_window(window: MainWindow, widget: QWidget) -> QRect:
    return QRect(widget.mapTo(window, QPoint(0, 0)), widget.size())


def test_viewport_gets_most_of_the_window(qtbot, window: MainWindow) -> None:
    window.layout_keeper.reset()
    settle(qtbot, window, DEFAULT_SIZE)
    assert window.layout_keeper.viewport_fraction() >= 0.60
    for dock in window.docks:  # every panel is there: tabbed, not hidden
        assert not dock.isHidden(), dock.windowTitle()
    tabbed = window.tabifiedDockWidgets(window.scene_dock)
    assert {window.settings_dock, window.clip_dock, window.stats_dock} <= set(tabbed)


def test_window_fits_a_1366x768_screen(qtbot, window: MainWindow) -> None:
    hint = window.minimumSizeHint()
    assert hint.width() <= 1366 and hint.height() <= 740
    settle(qtbot, window, (1366, 740))
    inside = window.rect()
    for part in (window.timeline_dock, window.timeline.play_button, window.statusBar(), window.status_label,
                 window.tf_editor.canvas.parentWidget()):
        assert part.isVisible()
        assert inside.contains(rect_in_window(window, part)), part
    assert window.layout_keeper.viewport_fraction() >= 0.55


def test_layout_persists_between_launches_and_resets(qtbot, tmp_path: Path) -> None:
    ini = str(tmp_path / "settings.ini")

    def launch() -> MainWindow:
        win = MainWindow(settings=QSettings(ini, QSettings.Format.IniFormat), recovery_dir=tmp_path / "recovery")
        win.show()
        qtbot.waitExposed(win)
        return win

    first = launch()
    settle(qtbot, first, (780, 560))  # within pytest-xvfb's 800x600 screen
    first.stats_dock.hide()
    first.removeDockWidget(first.clip_dock)
    first.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, first.clip_dock)
    first.clip_dock.show()
    qtbot.wait(50)
    first.close()
    gc.collect()

    second = launch()
    qtbot.wait(50)
    assert second.size().toTuple() == (780, 560)
    assert second.stats_dock.isHidden()
    assert second.dockWidgetArea(second.clip_dock) == Qt.DockWidgetArea.LeftDockWidgetArea
    reset = next(a for a in second.menuBar().actions()[2].menu().actions() if a.text() == "Reset &Layout")
    reset.trigger()
    qtbot.wait(50)
    assert second.size().toTuple() == second.layout_keeper.default_size()
    assert not second.stats_dock.isHidden()
    assert second.dockWidgetArea(second.clip_dock) == Qt.DockWidgetArea.RightDockWidgetArea
    second.close()
    gc.collect()


def controls(content: QWidget) -> list[QWidget]:
    """The controls a user works in ``content``: buttons, boxes, sliders, lists, editors (not the parts inside
    another control, such as a combo box's list or a tree's header)."""
    def inside_another(w: QWidget) -> bool:
        parent = w.parentWidget()
        while parent is not None and parent is not content:
            if isinstance(parent, CONTROLS) or parent.inherits("QComboBoxPrivateContainer"):
                return True
            parent = parent.parentWidget()
        return False

    return [w for w in content.findChildren(QWidget) if isinstance(w, CONTROLS) and not inside_another(w)]


def test_every_control_in_every_dock_has_a_tooltip(window: MainWindow) -> None:
    missing = []
    for dock in window.docks:
        content = dock.widget()
        found = controls(content.widget() if isinstance(content, QScrollArea) else content)
        missing += [f"{dock.windowTitle()}: {type(c).__name__} {getattr(c, 'text', str)()}" for c in found
                    if not c.toolTip()]
    assert not missing, missing
    assert window.tf_editor.canvas.toolTip()
    assert all(label.toolTip() for label in window.statistics.labels.values())  # a dock of read-outs only
    hint = window.tf_editor.hint  # the editor's gestures, under it
    assert hint.isVisibleTo(window) and "right-click" in hint.text() and "double-click" in hint.text()


def test_help_shortcuts_lists_every_action_and_about_names_the_versions(qtbot, window: MainWindow) -> None:
    from PySide6.QtGui import QAction

    dialog = window.help.show_shortcuts()
    qtbot.waitUntil(dialog.isVisible)
    listed = {dialog.table.item(r, 2).text() for r in range(dialog.table.rowCount())}
    with_keys = [a for a in window.findChildren(QAction) if not a.shortcut().isEmpty() and a.isVisible()]
    assert with_keys
    for action in with_keys:
        assert action.text().replace("&", "").replace("…", "").strip() in listed, action.text()
    assert "move forward" in listed
    dialog.reject()

    box = window.help.show_about()
    qtbot.waitUntil(box.isVisible)
    text = box.text()
    for needle in ("volviz", "VTK 9", "Qt 6", "PyVista", "OpenGL renderer: "):
        assert needle in text
    assert "OpenGL renderer: unknown" not in text
    box.accept()
