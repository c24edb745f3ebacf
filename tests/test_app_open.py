"""Opening files as a user does, under Xvfb: dropping files and folders on the window, a failed open that keeps the
scene on screen and says what is wrong in the user's terms, and File > Open Recent."""
from __future__ import annotations

import warnings
from pathlib import Path

from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDragEnterEvent, QDropEvent
from PySide6.QtWidgets import QApplication

from conftest import data_file
from test_app_window import wait_loaded, window  # noqa: F401  (the fixture)
from volviz_app.window import MainWindow


def drop(target, paths: list[Path]) -> bool:
    """Drag ``paths`` (file URLs, as a file manager gives them) onto ``target`` and drop them there: a real drag-enter
    event, then the drop (Qt delivers a drop only to the widget that accepted the drag). True: both were accepted."""
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(p)) for p in paths])
    centre = QPoint(target.width() // 2, target.height() // 2)
    buttons, keys = Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
    with warnings.catch_warnings():  # PySide6 marks the QPoint form deprecated; the QPointF one has no binding
        warnings.simplefilter("ignore", DeprecationWarning)
        enter = QDragEnterEvent(centre, Qt.DropAction.CopyAction, mime, buttons, keys)
    QApplication.sendEvent(target, enter)
    entered = enter.isAccepted()
    event = QDropEvent(QPointF(centre), Qt.DropAction.CopyAction, mime, buttons, keys)
    QApplication.sendEvent(target, event)
    return entered and event.isAccepted()


def props(window: MainWindow) -> list[str]:
    """The renderer's props by their C++ addresses (a Python wrapper may be made anew for each lookup)."""
    items = window.plotter.renderer.GetViewProps()
    return [items.GetItemAsObject(i).__this__ for i in range(items.GetNumberOfItems())]


def test_drop_a_file_on_the_window_or_viewport_opens_it(qtbot, window: MainWindow) -> None:
    neghip, fin = data_file("volumes/neghip.slc"), data_file("bluntfin/bluntfinxyz.bin")
    assert drop(window, [neghip])
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: "neghip.slc" in window.windowTitle())
    assert window.session.datasets[0].path == str(neghip.resolve())
    assert drop(window.plotter.interactor, [fin])  # the viewport's own drop handling would add a bare mesh
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: "bluntfinxyz.bin" in window.windowTitle())
    assert list(window.controller.props) == ["data"]


def test_drop_a_folder_opens_it_as_a_data_path(qtbot, window: MainWindow, tmp_path: Path) -> None:
    folder = tmp_path / "empty case"
    folder.mkdir()
    assert drop(window, [folder])
    qtbot.waitUntil(lambda: window.error_dialog is not None or window.controller is not None, timeout=30000)
    # whether or not a reader takes this folder, it was opened as a data path: a scene or a message naming it
    assert window.controller is not None or "empty case" in window.error_dialog.text()


def test_failed_open_keeps_the_scene_and_names_the_file(qtbot, window: MainWindow, tmp_path: Path) -> None:
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    before, title, session = props(window), window.windowTitle(), window.session
    bad = tmp_path / "x.vtu"
    bad.write_text("this is a text file, not a mesh\n")
    window.open_path(bad)
    qtbot.waitUntil(lambda: window.error_dialog is not None, timeout=30000)
    text = window.error_dialog.text()
    assert window.error_dialog.isVisible()
    assert "x.vtu" in text and "Check that the file is complete" in text
    assert "Traceback" not in text and "Error:" not in text and str(tmp_path) + "/x.vtu" not in text
    wait_loaded(qtbot, window)
    assert props(window) == before and window.windowTitle() == title and window.session is session
    assert "x.vtu" not in " ".join(window.recent_files())
    window.error_dialog.accept()


def test_open_recent_lists_only_files_that_opened_and_drops_missing_ones(qtbot, window: MainWindow,
                                                                         tmp_path: Path) -> None:
    good = data_file("volumes/neghip.slc")
    missing = tmp_path / "gone.slc"
    window.open_path(missing)
    qtbot.waitUntil(lambda: window.error_dialog is not None)
    assert "gone.slc" in window.error_dialog.text() and "does not exist" in window.error_dialog.text()
    window.error_dialog.accept()
    window.open_path(good)
    wait_loaded(qtbot, window)
    assert window.recent_files() == [str(good.resolve())]
    assert [a.text() for a in window.recent_menu.actions()] == [str(good.resolve())]
    assert window.recent.last_folder() == str(good.resolve().parent)
    dialog = window.ask_file("Open data", "All files (*)", lambda path: None)
    assert Path(dialog.directory().absolutePath()) == good.resolve().parent  # starts where the last file was
    dialog.reject()

    temporary = tmp_path / "copy.slc"
    temporary.write_bytes(good.read_bytes())
    window.open_path(temporary)
    wait_loaded(qtbot, window)
    assert window.recent_files()[0] == str(temporary.resolve())
    temporary.unlink()
    window.recent.refresh()
    assert window.recent_files() == [str(good.resolve())]
    window.recent_menu.actions()[0].trigger()
    wait_loaded(qtbot, window)
    assert "neghip.slc" in window.windowTitle()
