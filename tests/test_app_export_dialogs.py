"""File > Export Screenshot and Export Movie under Xvfb: exactly the size set (not the viewport's aspect, issue #28),
the format the extension names or a message refusing it, and an orbit movie without a recorded camera path."""
from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import pytest
from PIL import Image
from PySide6.QtCore import Qt

from conftest import data_file
from test_app_window import wait_loaded, window  # noqa: F401  (the fixture)
from test_flow_export import choose_file
from volviz_app.export_dialogs import ORBIT
from volviz_app.window import MainWindow


@pytest.fixture
def neghip_window(qtbot, window: MainWindow) -> MainWindow:  # noqa: F811
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    values = window.render_settings.settings()
    values["size"] = (240, 100)  # the export size, whatever the viewport's shape
    window.render_settings.load_values(values)
    window._settings_changed(values)
    return window


@pytest.mark.parametrize("name, magic", [("shot.jpg", b"\xff\xd8\xff"), ("shot.tiff", b"II*\x00")])
def test_screenshot_has_the_size_set_and_the_extension_format(qtbot, neghip_window: MainWindow,
                                                              tmp_path: Path, name: str, magic: bytes) -> None:
    window = neghip_window
    target = tmp_path / name
    assert window.export_dialogs.screenshot(target)
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=60000)
    assert window.export_result, window.status_label.text()
    assert target.read_bytes()[:len(magic)] == magic
    with Image.open(target) as image:
        width, height = image.size
    assert (width, height) == (240, 100)


def test_unknown_image_format_is_refused_with_a_message(qtbot, neghip_window: MainWindow, tmp_path: Path) -> None:
    window = neghip_window
    target = tmp_path / "shot.bmp"
    assert not window.export_dialogs.screenshot(target)
    assert window.error_dialog is not None and window.error_dialog.isVisible()
    text = window.error_dialog.text()
    assert ".bmp" in text and ".png" in text and "Traceback" not in text
    assert not target.exists() and window.export_result is None
    window.error_dialog.accept()


def test_orbit_movie_needs_no_recorded_path(qtbot, neghip_window: MainWindow, tmp_path: Path) -> None:
    """File > Export Movie, the orbit (no recorded path), 64x48 at 1 frame per second typed into the dialog: a folder
    of 8 frames (one turn of 8 s) of that size, the camera going round (the dialog had no size or frame rate: the
    movie took the render settings' size at 24 frames per second)."""
    window = neghip_window
    assert not window.session.camera_paths
    dialog = window.export_dialogs.ask_movie()
    qtbot.waitUntil(dialog.isVisible)
    assert dialog.comboBoxItems()[0] == ORBIT
    assert (dialog.width_box.value(), dialog.height_box.value(), dialog.fps.value()) == (240, 100, 24.0)
    dialog.setTextValue(ORBIT)
    for box, text in ((dialog.width_box, "64"), (dialog.height_box, "48"), (dialog.fps, "1")):
        box.setFocus()
        qtbot.keyClick(box, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
        qtbot.keyClicks(box, text)
    dialog.accept()
    frames = tmp_path / "orbit"
    choose_file(qtbot, window, "Export movie", frames)
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    assert window.export_result, window.status_label.text()
    written = sorted(frames.glob("frame_*.png"))
    assert len(written) == 8  # one turn of 8 s at 1 frame per second
    assert iio.imread(written[0]).shape[:2] == (48, 64)
    assert (iio.imread(written[0]) != iio.imread(written[2])).any()  # the camera went round
