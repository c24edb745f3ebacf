"""The application skeleton under Xvfb: real window, real VTK viewport, the menu's code paths."""
from __future__ import annotations

import gc

from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import data_file
from PySide6.QtCore import QSettings

pytest.importorskip("PySide6")

from volviz_app.window import MainWindow  # noqa: E402


def viewport_image(window: MainWindow) -> np.ndarray:
    window.plotter.render()
    return np.asarray(window.plotter.screenshot(None, return_img=True))


def not_blank(image: np.ndarray) -> float:
    """Fraction of pixels that differ clearly from the corner (background) color."""
    background = image[0, 0, :3].astype(int)
    return float((np.abs(image[..., :3].astype(int) - background).sum(axis=2) > 30).mean())


@pytest.fixture
def window(qtbot, tmp_path):
    win = MainWindow(settings=QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat),
                     recovery_dir=tmp_path / "recovery")
    win.resize(640, 480)
    win.show()
    qtbot.waitExposed(win)
    yield win
    win.dirty = False
    win.close()
    gc.collect()  # free the closed window here, on the GUI thread


def wait_loaded(qtbot, window: MainWindow, timeout: int = 60000) -> None:
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible(), timeout=timeout)


def test_demo_scene_renders(qtbot, window: MainWindow) -> None:
    window.open_demo()
    wait_loaded(qtbot, window)
    assert window.status_label.text() == "Showing demo scene"
    assert not_blank(viewport_image(window)) > 0.02


def test_open_blunt_fin_through_menu_code_path(qtbot, window: MainWindow) -> None:
    path = data_file("bluntfin/bluntfinxyz.bin")
    window.open_path(path)
    wait_loaded(qtbot, window)
    assert window.error_dialog is None, window.error_dialog.text()
    assert "bluntfinxyz.bin" in window.windowTitle()
    assert not_blank(viewport_image(window)) > 0.02


def test_bad_file_gives_error_dialog_and_app_keeps_working(qtbot, window: MainWindow, tmp_path: Path) -> None:
    bad = tmp_path / "bad.pvm"
    bad.write_bytes(b"PVM\n28 28 23\n1\n" + b"\x01" * 10)  # truncated
    window.open_path(bad)
    qtbot.waitUntil(lambda: window.error_dialog is not None, timeout=30000)
    assert window.error_dialog.isVisible()
    assert "bad.pvm" in window.error_dialog.text()
    window.error_dialog.accept()
    window.open_demo()
    wait_loaded(qtbot, window)
    assert window.status_label.text() == "Showing demo scene"


def test_save_session_and_export_screenshot(qtbot, window: MainWindow, tmp_path: Path) -> None:
    source = data_file("volumes/neghip.slc")
    window.open_path(source)
    wait_loaded(qtbot, window)
    window.plotter.camera.azimuth = 30.0
    session_file = tmp_path / "s" / "neghip.json"
    session_file.parent.mkdir()
    assert window.save_session(session_file)

    from volviz.session import load

    saved = load(session_file)
    assert not Path(saved.datasets[0].path).is_absolute()  # stored relative to the session file
    assert (session_file.parent / saved.datasets[0].path).resolve() == Path(source).resolve()
    assert saved.camera is not None

    shot = tmp_path / "shot.png"
    window.export_screenshot(shot, size=(300, 200))
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=60000)  # rendered in the background
    assert window.export_result
    image = iio.imread(shot)
    assert image.shape[:2] == (200, 300)
    assert not_blank(image) > 0.02

    window.open_path(session_file)
    wait_loaded(qtbot, window)
    assert window.session_path == session_file
    assert np.allclose(window.plotter.camera.position, saved.camera.position)
