"""Dialogs and docks at the window's default size on a laptop (issue #28, a new user on a 1366x768 screen): the
Isosurfaces dock showed its table's empty rows and hid its Add/Apply/Remove buttons below the fold, and the Open
dialog came up at 632x412, which cut its Size and Date columns."""
from __future__ import annotations

from PySide6.QtCore import QRect, Qt
from PySide6.QtWidgets import QHeaderView, QScrollArea, QTreeView

from conftest import data_file
from flows import wait_loaded, wait_settled
from test_flow_newuser_layout import LAPTOP, _side_tabs


def _laptop_window(qtbot, make_window):
    """A window at the laptop's default size, its docks laid out as on a first start at that size."""
    window = make_window()
    for reset in (True, False):
        window.resize(*LAPTOP)
        qtbot.waitUntil(lambda: window.size().toTuple() == LAPTOP)
        if reset:
            window.layout_keeper.reset()
    qtbot.wait(100)            # the docks are laid out in the event loop
    return window


def test_iso_dock_buttons_are_in_view_without_scrolling(qtbot, make_window) -> None:
    window = _laptop_window(qtbot, make_window)
    window.open_demo()         # as `volviz-app` starts: the demo has no volume, and the dock says so in its note
    wait_loaded(qtbot, window)
    assert window.iso_tool.dock.note.text()
    window.dirty = False
    window.open_path(data_file("volumes/hydrogen.vti"))   # as the new user did: data whose surfaces the dock adds
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    bar = _side_tabs(window)
    index = next(i for i in range(bar.count()) if bar.tabText(i) == window.iso_dock.windowTitle())
    window.iso_dock.raise_()   # as the tab's click does (test_flow_newuser_layout clicks every tab)
    qtbot.waitUntil(lambda: bar.currentIndex() == index and window.iso_dock.widget().isVisible())
    dock = window.iso_tool.dock
    dock.value.selectAll()
    qtbot.keyClicks(dock.value, "0.05")
    qtbot.mouseClick(dock.add_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: dock.table.rowCount() == 1)
    wait_settled(qtbot, window)
    qtbot.wait(200)            # laid out in the event loop
    area = window.iso_dock.widget()
    assert isinstance(area, QScrollArea)
    assert area.verticalScrollBar().value() == 0
    seen = QRect(area.viewport().mapTo(window, area.viewport().rect().topLeft()), area.viewport().size())
    for button in (dock.add_button, dock.apply_button, dock.remove_button, dock.mode):
        assert button.isVisible()
        box = QRect(button.mapTo(window, button.rect().topLeft()), button.size())
        assert seen.contains(box), (button.text() if hasattr(button, "text") else "mode", box, seen)


def test_open_dialog_shows_its_columns_whole(qtbot, make_window) -> None:
    window = _laptop_window(qtbot, make_window)
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window, Qt.Key.Key_O, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: getattr(window.session_files, "file_dialog", None) is not None
                    and window.session_files.file_dialog.isVisible())
    dialog = window.session_files.file_dialog
    qtbot.wait(100)
    screen = window.screen().availableGeometry()
    assert screen.contains(dialog.frameGeometry()), (dialog.frameGeometry(), screen)
    # most of the window, or of the screen where that is smaller (pytest-xvfb's screen is 800x600)
    assert dialog.width() >= min(0.7 * window.width(), screen.width() - 50), (dialog.size(), screen)
    assert dialog.height() >= min(0.7 * window.height(), screen.height() - 50), (dialog.size(), screen)
    view = next(v for v in dialog.findChildren(QTreeView) if v.isVisible())
    header: QHeaderView = view.header()
    for column in range(header.count()):    # Name, Size, Type, Date Modified: none runs past the list's right edge
        end = header.sectionViewportPosition(column) + header.sectionSize(column)
        assert end <= view.viewport().width(), (column, end, view.viewport().width())
    dialog.reject()
