"""Flows that would replace or lose unsaved work, in the real window (issue #28)."""
from __future__ import annotations

import json
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QMessageBox

from conftest import data_file
from flows import wait_loaded
from test_app_open import drop


def _add_plane(qtbot, window) -> None:
    """A user's edit: Clipping > Add plane, clicked."""
    window.clip_dock.show()
    window.clip_dock.raise_()
    qtbot.mouseClick(window.clipping.add_button, Qt.MouseButton.LeftButton)
    assert window.dirty and window.windowTitle().endswith("*")


def _answer(qtbot, window, button: QMessageBox.StandardButton) -> None:
    qtbot.waitUntil(lambda: getattr(window, "unsaved_dialog", None) is not None
                    and window.unsaved_dialog.isVisible())
    qtbot.mouseClick(window.unsaved_dialog.button(button), Qt.MouseButton.LeftButton)


def test_open_over_unsaved_work_asks_and_cancel_keeps_it(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    _add_plane(qtbot, window)
    planes = len(window.session.clip.planes)

    window.action_open_data.trigger()      # File > Open Data: the question comes before the file dialog
    _answer(qtbot, window, QMessageBox.StandardButton.Cancel)
    qtbot.wait(200)
    assert getattr(window, "file_dialog", None) is None or not window.file_dialog.isVisible()
    assert window.dirty and "neghip.slc" in window.windowTitle()
    assert len(window.session.clip.planes) == planes

    window.action_open_data.trigger()
    _answer(qtbot, window, QMessageBox.StandardButton.Discard)
    qtbot.waitUntil(lambda: window.file_dialog.isVisible())
    window.file_dialog.selectFile(str(data_file("volumes/hydrogen.vti")))
    window.file_dialog.accept()
    qtbot.waitUntil(lambda: "hydrogen.vti" in window.windowTitle(), timeout=60000)
    wait_loaded(qtbot, window)
    assert not window.dirty


def test_drop_over_unsaved_work_asks_and_save_saves_first(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    session = tmp_path / "neghip.json"
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    assert window.save_session(session)
    _add_plane(qtbot, window)

    assert drop(window.plotter.interactor, [data_file("volumes/hydrogen.vti")])
    _answer(qtbot, window, QMessageBox.StandardButton.Save)
    qtbot.waitUntil(lambda: "hydrogen.vti" in window.windowTitle(), timeout=60000)
    wait_loaded(qtbot, window)
    saved = json.loads(session.read_text())
    assert len(saved["clip"]["planes"]) == 1     # the edit was saved before the other file replaced it


def test_recovery_file_follows_each_edit_within_seconds(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    assert not window.recovery_file.exists()
    _add_plane(qtbot, window)
    # within seconds (the periodic autosave alone came after 60 s): what a kill now leaves holds the plane
    qtbot.waitUntil(window.recovery_file.exists, timeout=10000)
    kept = json.loads(window.recovery_file.read_text())
    assert len(kept["clip"]["planes"]) == 1       # the plane added a moment ago is in what a crash leaves

