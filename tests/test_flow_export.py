"""Flow tests of File > Export Screenshot and Export Movie in the real window under Xvfb (issue #28): open, save the
session through the menu, export through the menu's dialogs, and hold the written image to ``volviz render`` of the
saved session at the same camera and size.

The error bound: the export and ``volviz render`` draw with the same methods offscreen (the natural scene's CPU
terrain, fog and cloud images, VTK's ray caster on llvmpipe) at the same camera and size, so the methods' own errors
against their references cancel, and what is left is 8-bit rounding. Measured (this machine): RMSE 0.00 / max 0 for
opaque images (Yukon 512x384, neghip at twice the window); a transparent export (neghip 700x300), its straight color
rounded to 8 bits and composited over the background again into 8 bits, RMSE 0.11 / max 1.0. Bound: RMSE <= 0.5 and
max <= 2 (one rounding step on each side). The defect of issue #28 (no clouds or fog: the overlay computed at the
8x8 warm-up size) was RMSE 43.4 / max 237 at 512x384 in these tests with the fix taken out.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from PySide6.QtCore import Qt

from conftest import REPO, data_file, data_root
from volviz_app.window import MainWindow

RMSE_BOUND = 0.5   # 8-bit units (see the module's docstring)
MAX_BOUND = 2.0
YUKON = REPO / "resources" / "sessions" / "yukon.json"


@pytest.fixture
def data_env(monkeypatch: pytest.MonkeyPatch) -> None:
    """The shipped sessions name their data under $VOLVIZ_DATA."""
    data_file("yukon/Yukon.map.pgm")
    monkeypatch.setenv("VOLVIZ_DATA", str(data_root()))


def wait_loaded(qtbot, window: MainWindow) -> None:
    qtbot.waitUntil(lambda: window.controller is not None and not window.progress_bar.isVisible(), timeout=180000)
    assert window.error_dialog is None, window.error_dialog.text()


def choose_file(qtbot, window: MainWindow, title: str, path: Path) -> None:
    """Answer the file dialog the menu opened (non-native: typed into as a user would)."""
    qtbot.waitUntil(lambda: getattr(window, "file_dialog", None) is not None and window.file_dialog.isVisible())
    dialog = window.file_dialog
    assert dialog.windowTitle() == title
    dialog.selectFile(str(path))
    dialog.accept()


def save_as(qtbot, window: MainWindow, path: Path) -> None:
    window.action_save_session_as.trigger()
    choose_file(qtbot, window, "Save session", path)
    qtbot.waitUntil(lambda: window.session_path == path)


def export_through_menu(qtbot, window: MainWindow, path: Path, size: tuple[int, int] | None = None,
                        scale: float | None = None, transparent: bool = False) -> None:
    """File > Export Screenshot: the size typed (or the window's size times ``scale``), OK, the file; wait."""
    window.action_export_screenshot.trigger()
    dialog = window.export_dialogs.screenshot_dialog
    qtbot.waitUntil(lambda: dialog is not None and dialog.isVisible())
    if size is not None:
        for box, value in ((dialog.width_box, size[0]), (dialog.height_box, size[1])):
            box.setFocus()
            qtbot.keyClick(box, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
            qtbot.keyClicks(box, str(value))
    if scale is not None:
        qtbot.mouseClick(dialog.of_window, Qt.MouseButton.LeftButton)
        dialog.scale.setFocus()
        qtbot.keyClick(dialog.scale, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
        qtbot.keyClicks(dialog.scale, f"{scale:g}")
    if transparent:
        qtbot.mouseClick(dialog.transparent, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(dialog.ok_button, Qt.MouseButton.LeftButton)
    choose_file(qtbot, window, "Export screenshot", path)
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=180000)
    assert window.export_result, window.status_label.text()


def volviz_render(session: Path, out: Path, size: tuple[int, int], *options: str) -> np.ndarray:
    """``volviz render SESSION -o OUT --size WxH [OPTIONS]``, the command a user runs; the image (a movie's first
    frame)."""
    result = subprocess.run([sys.executable, "-m", "volviz.cli", "render", str(session), "-o", str(out), "--size",
                             f"{size[0]}x{size[1]}", *options], capture_output=True, text=True, timeout=600,
                            env={**os.environ, "VOLVIZ_DATA": str(data_root())})
    assert result.returncode == 0, result.stderr
    return read_png(out / "frame_00000.png" if options else out)


def read_png(path: Path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image).astype(np.float64)


def premultiplied(image: np.ndarray) -> np.ndarray:
    """RGBA 0..255 float, color premultiplied (an opaque image gets alpha 255)."""
    if image.shape[2] == 3:
        return np.concatenate([image, np.full(image.shape[:2] + (1,), 255.0)], axis=2)
    alpha = image[..., 3:] / 255.0
    return np.concatenate([image[..., :3] * alpha, image[..., 3:]], axis=2)


def over(image: np.ndarray, background: tuple[float, float, float]) -> np.ndarray:
    """A straight-alpha RGBA image composited over the opaque ``background`` (RGB 0..1): RGB 0..255 float."""
    alpha = image[..., 3:] / 255.0
    return image[..., :3] * alpha + (1.0 - alpha) * np.asarray(background)[:3] * 255.0


def errors(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """(RMSE, max abs) of premultiplied RGBA in 8-bit units."""
    assert a.shape[:2] == b.shape[:2]
    d = premultiplied(a) - premultiplied(b)
    return float(np.sqrt(np.mean(d ** 2))), float(np.abs(d).max())


def assert_within_bound(a: np.ndarray, b: np.ndarray, outliers: float = 0.0) -> None:
    """RMSE and max within the bound; ``outliers``: the share of pixels allowed past ``MAX_BOUND``."""
    rmse, worst = errors(a, b)
    beyond = float((np.abs(premultiplied(a) - premultiplied(b)).max(axis=2) > MAX_BOUND).mean())
    assert rmse <= RMSE_BOUND and (worst <= MAX_BOUND or beyond <= outliers), \
        f"RMSE {rmse:.3f}, max {worst:.1f} (8-bit units), {beyond:.2e} of the pixels past {MAX_BOUND}"


@pytest.fixture
def yukon(qtbot, make_window, data_env, tmp_path: Path) -> tuple[MainWindow, Path]:
    """The shipped Yukon session, open, saved again through File > Save Session As."""
    window = make_window()
    window.open_path(YUKON)
    wait_loaded(qtbot, window)
    saved = tmp_path / "yukon-saved.json"
    save_as(qtbot, window, saved)
    return window, saved


def test_yukon_screenshot_keeps_the_clouds_and_fog_at_the_size_set(qtbot, yukon, tmp_path: Path) -> None:
    """Issue #28: the PNG showed bare terrain (no clouds, no ground fog), 512x365 where 512x384 was set."""
    window, saved = yukon
    assert tuple(window.session.render.size) == (512, 384)
    shot = tmp_path / "yukon.png"
    export_through_menu(qtbot, window, shot)
    image = read_png(shot)
    assert image.shape == (384, 512, 3)
    reference = volviz_render(saved, tmp_path / "reference.png", (512, 384))
    assert_within_bound(image, reference)


def test_yukon_movie_frame_0_is_the_screenshot(qtbot, yukon, tmp_path: Path) -> None:
    """The movie's first frame had lost the clouds and fog like the screenshot. It matches ``volviz render --orbit``'s
    first frame within the bound. Against the still image a movie frame differs in a few terrain pixels: setting a
    frame's camera refits VTK's clipping range (near 6.5 instead of the still's 1.0), which moves them (measured: 5 of
    196,608 pixels, max 12, RMSE 0.04; with the still's range restored, none), so 1e-4 of the pixels may pass the
    max bound there."""
    window, saved = yukon
    shot = tmp_path / "yukon.png"
    assert window.export_dialogs.screenshot(shot)
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=180000)
    assert window.export_result, window.status_label.text()
    frames = tmp_path / "orbit"
    window.export_movie(frames, None, through_time=False, fps=0.5, orbit=True)  # 4 frames over one turn
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=300000)
    assert window.export_result, window.status_label.text()
    assert len(list(frames.glob("frame_*.png"))) == 4
    frame0, screenshot = read_png(frames / "frame_00000.png"), read_png(shot)
    assert frame0.shape == screenshot.shape == (384, 512, 3)
    assert_within_bound(frame0, volviz_render(saved, tmp_path / "reference", (512, 384), "--orbit", "--fps", "0.5"))
    assert_within_bound(frame0, screenshot, outliers=1e-4)


@pytest.fixture
def neghip(qtbot, make_window, tmp_path: Path) -> tuple[MainWindow, Path]:
    """neghip.slc (a regular volume in empty space) open in a 640x480 window, its session saved through the menu."""
    window = make_window()
    window.resize(640, 480)
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    saved = tmp_path / "neghip.json"
    save_as(qtbot, window, saved)
    return window, saved


def test_export_dialog_size_of_another_shape_with_a_transparent_background(qtbot, neghip, tmp_path: Path) -> None:
    """A figure without the box, axes and scalar bar (View menu), transparent. (With them, the antialiased edges of
    lines and text do not composite back exactly: this driver resolves multisampling in linear light, which no
    straight-alpha 8-bit image reproduces; measured 0.76 % of the pixels at 700x300, max 61.)"""
    window, _ = neghip
    for action in window.decorations.actions.values():
        action.trigger()
        assert not action.isChecked()
    saved = tmp_path / "neghip-figure.json"
    save_as(qtbot, window, saved)
    viewport = tuple(window.plotter.window_size)
    size = (700, 300)
    assert abs(size[0] / size[1] - viewport[0] / viewport[1]) > 0.5  # not the window's shape
    shot = tmp_path / "neghip.png"
    export_through_menu(qtbot, window, shot, size=size, transparent=True)
    with Image.open(shot) as png:
        assert png.size == size and png.mode == "RGBA"
    image = read_png(shot)
    reference = volviz_render(saved, tmp_path / "reference.png", size)
    background = window.session.render.background
    alpha = image[..., 3]
    # nothing drawn: alpha 0 (half the picture at least, the corners among it) and the reference shows the bare
    # background there; the volume is partly opaque
    assert (alpha == 0).mean() > 0.5 and alpha[0, 0] == alpha[-1, 0] == alpha[0, -1] == alpha[-1, -1] == 0
    bare = np.abs(reference - np.asarray(background)[:3] * 255.0).max(axis=2) <= 1.0
    assert bare[alpha == 0].all()
    assert (alpha[(alpha > 0) & (alpha < 255)]).size > 1000 and alpha.max() > 128
    assert_within_bound(np.rint(over(image, background)), reference)  # a viewer writes 8 bits


def test_export_dialog_scale_of_the_window(qtbot, neghip, tmp_path: Path) -> None:
    window, saved = neghip
    width, height = window.plotter.window_size
    shot = tmp_path / "neghip-2x.png"
    export_through_menu(qtbot, window, shot, scale=2.0)
    image = read_png(shot)
    assert image.shape == (2 * height, 2 * width, 3)
    assert_within_bound(image, volviz_render(saved, tmp_path / "reference.png", (2 * width, 2 * height)))


def test_a_transparent_jpeg_is_refused_before_rendering(qtbot, neghip, tmp_path: Path) -> None:
    window, _ = neghip
    target = tmp_path / "shot.jpg"
    assert not window.export_dialogs.screenshot(target, (64, 48), transparent=True)
    assert window.error_dialog is not None and window.error_dialog.isVisible()
    assert "JPEG has no transparency" in window.error_dialog.text() and "shot.jpg" in window.error_dialog.text()
    assert not target.exists() and window.export_result is None
    window.error_dialog.accept()
