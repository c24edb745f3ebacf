"""A file that crashes VTK's reader, opened in the app under Xvfb: the reader's child process dies, the window shows
the error dialog naming the file, and the scene that was open stays (the app process itself never sees the crash)."""
from __future__ import annotations

from pathlib import Path

import isolation_loaders
from conftest import data_file, make_window  # noqa: F401  (the fixture)
from test_app_open import props
from test_app_window import wait_loaded


def test_a_file_that_crashes_vtk_shows_the_error_and_keeps_the_scene(qtbot, make_window, tmp_path: Path,  # noqa: F811
                                                                     monkeypatch) -> None:
    isolation_loaders.register(monkeypatch)
    window = make_window()
    window.open_path(data_file("volumes/hydrogen.vti"))
    wait_loaded(qtbot, window)
    before, title, session = props(window), window.windowTitle(), window.session
    assert before and "hydrogen.vti" in title

    crash = isolation_loaders.crash_vti(tmp_path / "damaged.uvti")
    window.open_path(crash)
    qtbot.waitUntil(lambda: window.error_dialog is not None, timeout=60000)
    text = window.error_dialog.text()
    assert window.error_dialog.isVisible()
    assert "damaged.uvti" in text and "crashed (segmentation fault)" in text
    wait_loaded(qtbot, window)
    assert props(window) == before and window.windowTitle() == title and window.session is session
    window.error_dialog.accept()

    window.open_path(data_file("volumes/ironProt.vtk"))  # the app reads on as before
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: "ironProt.vtk" in window.windowTitle(), timeout=60000)
