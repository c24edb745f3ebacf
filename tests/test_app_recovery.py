"""Crash recovery with several windows: each window autosaves to its own file, a clean close deletes only its own
file, and the autosave of a really crashed process (SIGKILL) is offered to exactly one window."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import data_file

pytest.importorskip("PySide6")

from PySide6.QtWidgets import QMessageBox  # noqa: E402

from volviz_app.window import MainWindow  # noqa: E402

REPO = Path(__file__).resolve().parent.parent

CRASHING_APP = r"""
import os, signal, sys
from pathlib import Path
from PySide6.QtCore import QSettings, QTimer
from PySide6.QtWidgets import QApplication
from volviz_app.window import MainWindow

app = QApplication(sys.argv[:1])
window = MainWindow(settings=QSettings(sys.argv[3], QSettings.Format.IniFormat), recovery_dir=Path(sys.argv[1]))
window.show()
window.open_path(sys.argv[2])


def edit_autosave_and_crash():
    if window.controller is None or window.progress_bar.isVisible():
        QTimer.singleShot(50, edit_autosave_and_crash)
        return
    window.scene_tree.opacity.setValue(25)
    if window.autosave():
        print(window.recovery_file, flush=True)
    os.kill(os.getpid(), signal.SIGKILL)


QTimer.singleShot(0, edit_autosave_and_crash)
app.exec()
"""


def open_and_edit(qtbot, window: MainWindow, opacity: int) -> None:
    window.open_path(data_file("volumes/neghip.slc"))
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible() and window.controller is not None, timeout=60000)
    window.scene_tree.opacity.setValue(opacity)
    assert window.dirty


def test_two_windows_autosave_and_recover_independently(qtbot, make_window, tmp_path: Path) -> None:
    recovery = tmp_path / "recovery"
    recovery.mkdir()
    crash = subprocess.run([sys.executable, "-c", CRASHING_APP, str(recovery), str(data_file("volumes/neghip.slc")),
                            str(tmp_path / "crashed.ini")], capture_output=True, text=True, timeout=120,
                           env=dict(os.environ, PYTHONPATH=str(REPO)))
    assert crash.returncode == -9, crash.stderr[-2000:]
    orphan = Path(crash.stdout.strip())
    assert orphan.parent == recovery and orphan.exists()

    first, second = make_window(), make_window()
    assert first.recovery_file != second.recovery_file
    assert first.offer_recovery()  # claims the crashed process's file ...
    assert not second.offer_recovery()  # ... so the other window has nothing to offer
    qtbot.waitUntil(lambda: first.recovery_dialog is not None and first.recovery_dialog.isVisible())
    first.recovery_dialog.button(QMessageBox.StandardButton.Yes).click()
    qtbot.waitUntil(lambda: not first.progress_bar.isVisible() and first.controller is not None, timeout=60000)
    assert first.session.components[0].opacity == pytest.approx(0.25) and first.dirty
    assert not orphan.exists()

    open_and_edit(qtbot, second, 60)
    assert first.autosave() and second.autosave()
    assert {p.name for p in recovery.iterdir()} == {first.recovery_file.name, second.recovery_file.name}

    second.dirty = False
    second.close()  # a clean close deletes this window's autosave only
    assert not second.recovery_file.exists()
    assert first.recovery_file.exists()
    third = make_window()
    assert not third.offer_recovery()  # the first window is alive: its autosave is not an orphan
    assert first.recovery_file.exists()
