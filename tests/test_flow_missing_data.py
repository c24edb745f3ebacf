"""A session whose data files are missing: each is named, can be located, and the shown scene stays (issue #28)."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from PySide6.QtCore import Qt

from conftest import data_file, data_root
from flows import wait_loaded

SHIPPED = Path(__file__).resolve().parents[1] / "resources" / "sessions" / "yukon.json"


def test_cli_names_every_missing_file_and_the_variable(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("VOLVIZ_DATA", raising=False)
    proc = subprocess.run([sys.executable, "-m", "volviz.cli", "render", str(SHIPPED), "-o", str(tmp_path / "y.png")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode != 0 and "internal error" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    for name in ("Yukon.map.pgm", "Yukon.texmap.ppm", "Yukon.fogmap.pgm", "Yukon.fogmap1.pgm", "Yukon.fogmap2.pgm",
                 "SkyDome.ppm"):
        assert name in lines[0]
    assert "6 data files not found" in lines[0] and "set VOLVIZ_DATA" in lines[0]


def test_app_names_missing_files_locates_them_and_remembers_the_folder(qtbot, make_window, tmp_path: Path,
                                                                        monkeypatch) -> None:
    root, neghip, first = data_root(), data_file("volumes/neghip.slc"), data_file("yukon/Yukon.map.pgm")
    monkeypatch.delenv("VOLVIZ_DATA", raising=False)
    session = tmp_path / "yukon.json"
    shutil.copy(SHIPPED, session)
    window = make_window()
    window.open_path(neghip)
    wait_loaded(qtbot, window)
    shown = window.controller

    window.open_path(session)
    dialog = window.missing_dialog
    qtbot.waitUntil(dialog.isVisible)
    listed = [dialog.files.item(i).text() for i in range(dialog.files.count())]
    assert len(listed) == 6 and any("Yukon.map.pgm" in t for t in listed)
    assert "VOLVIZ_DATA" in dialog.label.text()
    assert window.controller is shown and "neghip.slc" in window.windowTitle()  # the shown scene stays

    qtbot.mouseClick(dialog.locate_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: dialog.folder_dialog is not None and dialog.folder_dialog.isVisible())
    dialog.folder_dialog.selectFile(str(root))
    dialog.folder_dialog.accept()
    qtbot.waitUntil(lambda: window.controller is not shown, timeout=120000)
    wait_loaded(qtbot, window, timeout=120000)
    assert window.error_dialog is None
    assert {c.id for c in window.session.components} >= {"terrain", "ground_fog", "cloud_layer", "sky"}
    assert window.session.datasets[0].path == str(first.resolve())

    again = make_window()         # the folder is remembered: the next open finds the files without asking
    again.open_path(session)
    wait_loaded(qtbot, again, timeout=120000)
    assert again.error_dialog is None and getattr(again, "missing_dialog", None) is None
