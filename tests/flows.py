"""Helpers of the flow tests: drive the real window with real input events and compare the picture the user is left
with against ``volviz render`` of the same session at the same camera and size."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication

from conftest import data_file
from volviz.optics.metrics import max_abs, rmse


def wait_loaded(qtbot, window, timeout: int = 60000) -> None:
    """Until the scene and its first views are shown."""
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible() and window.controller is not None, timeout=timeout)


def open_blunt_fin(qtbot, make_window):
    """A 900x650 window with the Blunt Fin (PLOT3D, a PT volume) opened and its first views shown."""
    window = make_window()
    window.resize(900, 650)
    window.open_path(data_file("bluntfin/bluntfinxyz.bin"))
    wait_loaded(qtbot, window)
    return window


def open_settled(qtbot, make_window, relative: str, size: tuple[int, int] = (1280, 740)):
    """A window of ``size`` (the default window on a 1366x768 laptop screen) with the shared dataset ``relative``
    opened and its final picture shown."""
    window = make_window()
    window.resize(*size)
    window.open_path(data_file(relative))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    return window


def wait_settled(qtbot, window, timeout: int = 60000) -> None:
    """Until no background job is running and the window is not busy: the view is at its final quality."""
    import time

    idle_since = [None]

    def drawing() -> bool:   # the still frame after an interaction is pending, or being drawn in strips
        strips, single = getattr(window, "still_strips", None), getattr(window, "single_render", None)
        return bool((strips is not None and strips.drawing) or (single is not None and single.settle.isActive()))

    def settled() -> bool:   # idle for 0.6 s in a row: edits wait on short timers (previews, cuts) before a job
        if window.progress_bar.isVisible() or window.jobs.busy() or drawing():
            idle_since[0] = None
            return False
        idle_since[0] = idle_since[0] or time.monotonic()
        return time.monotonic() - idle_since[0] > 0.6

    qtbot.waitUntil(settled, timeout=timeout)


def screen(window) -> np.ndarray:
    """The viewport's frame as the user sees it (the render window's pixels after one draw), RGB float."""
    window.plotter.render()
    return np.asarray(window.plotter.screenshot(None, return_img=True))[..., :3].astype(np.float64)


def _mouse(widget, kind: QEvent.Type, pos: QPointF, buttons: Qt.MouseButton,
           button: Qt.MouseButton = Qt.MouseButton.LeftButton) -> None:
    event = QMouseEvent(kind, pos, widget.mapToGlobal(pos), button, buttons, Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(widget, event)


def drag(qtbot, widget, start: QPoint, end: QPoint, steps: int = 8, button=Qt.MouseButton.LeftButton) -> None:
    """A real press-move-release sequence on ``widget`` delivered through Qt's event system."""
    a, b = QPointF(start), QPointF(end)
    _mouse(widget, QEvent.Type.MouseButtonPress, a, button, button)
    for k in range(1, steps + 1):
        _mouse(widget, QEvent.Type.MouseMove, a + (b - a) * (k / steps), button, button)
        qtbot.wait(30)
    _mouse(widget, QEvent.Type.MouseButtonRelease, b, Qt.MouseButton.NoButton, button)


def drag_viewport(qtbot, window, dx: int, dy: int = 0) -> None:
    """Orbit the camera by dragging across the middle of the viewport."""
    canvas = window.plotter.interactor
    c = QPoint(canvas.width() // 2, canvas.height() // 2)
    drag(qtbot, canvas, c, c + QPoint(dx, dy))


def render_saved(session: Path, size: tuple[int, int], out: Path) -> np.ndarray:
    """``volviz render SESSION -o OUT --size WxH`` in its own process (no Qt): the reference the screen is held to."""
    proc = subprocess.run([sys.executable, "-m", "volviz.cli", "render", str(session), "-o", str(out),
                           "--size", f"{size[0]}x{size[1]}"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return np.asarray(iio.imread(out))[..., :3].astype(np.float64)


def compare_with_render(window, tmp_path: Path, name: str = "flow") -> dict[str, float]:
    """Save the window's session, render it offscreen at the viewport's size and camera, and return the error of the
    on-screen frame against it (8-bit units: rmse, max; and the fraction of pixels off by more than 24)."""
    return _compare_with_render(window, tmp_path, name)[0]


def _compare_with_render(window, tmp_path: Path, name: str) -> tuple[dict[str, float], np.ndarray]:
    """``compare_with_render``'s error, and the on-screen frame it was measured on."""
    session = tmp_path / f"{name}.json"
    assert window.save_session(session)
    shown = screen(window)
    size = (shown.shape[1], shown.shape[0])
    ref = render_saved(session, size, tmp_path / f"{name}.png")
    assert ref.shape == shown.shape
    return {"rmse": rmse(shown / 255.0, ref / 255.0), "max": max_abs(shown / 255.0, ref / 255.0),
            "off": float((np.abs(shown - ref).max(axis=2) > 24).mean())}, shown


def assert_matches_render(window, tmp_path: Path, name: str = "flow", max_rmse: float = 2.0,
                          max_off: float = 0.01) -> dict[str, float]:
    """``compare_with_render`` held to its bounds (RMSE in 8-bit units, the share of pixels off by more than 24). On
    failure the screen grab is kept beside the reference (``NAME-screen.png`` and ``NAME.png``, with the session
    ``NAME.json``, in ``tmp_path``) and both paths are printed and named in the message, so that a failure on CI can
    be looked at."""
    err, shown = _compare_with_render(window, tmp_path, name)
    if not (err["rmse"] < max_rmse and err["off"] < max_off):
        grab = tmp_path / f"{name}-screen.png"
        iio.imwrite(grab, np.clip(np.rint(shown), 0, 255).astype(np.uint8))
        where = f"screen grab {grab}, reference {tmp_path / f'{name}.png'}"
        print(where)
        raise AssertionError(f"{err} (bounds: rmse < {max_rmse}, off < {max_off}); {where}")
    return err


def pick_combo_item(qtbot, combo, data: str) -> None:
    """Open ``combo``'s popup with a click and click the item whose data is ``data`` (as a user picks), then wait
    until the popup closed, the item taken (an action combo, such as the presets, shows its title again). The item
    is clicked once the double-click interval has passed since the popup showed:
    Qt's popup ignores a release that soon after it opened unless the pointer moved in it, and under load the X
    server's motion event can come after the click (once in CI the pick of "vtk" in the renderer combo was lost)."""
    import time

    from PySide6.QtCore import Qt as _Qt
    from PySide6.QtWidgets import QApplication

    index = combo.findData(data)
    index = index if index >= 0 else combo.findText(data)   # a combo of plain texts
    assert index >= 0, f"{data!r} is not offered: {[combo.itemData(i) for i in range(combo.count())]}"
    qtbot.mouseClick(combo, _Qt.MouseButton.LeftButton)
    view = combo.view()
    qtbot.waitUntil(view.isVisible)
    shown = time.monotonic()
    view.scrollTo(view.model().index(index, 0))  # as the user scrolls a long list
    qtbot.wait(50)
    rect = view.visualRect(view.model().index(index, 0))
    qtbot.mouseMove(view.viewport(), rect.center())  # the popup selects the item under the pointer
    rest_ms = QApplication.doubleClickInterval() + 50 - 1000 * (time.monotonic() - shown)
    qtbot.wait(max(50, int(rest_ms)))
    qtbot.mouseClick(view.viewport(), _Qt.MouseButton.LeftButton, pos=rect.center())
    qtbot.waitUntil(lambda: not view.isVisible(), timeout=5000)


def scalar_bar_ranges(window) -> list[tuple[float, float]]:
    """The value ranges the viewport's scalar bars show."""
    from volviz.render.decorations import scalar_bar_actor

    bar = scalar_bar_actor(window.plotter)
    return [] if bar is None else [tuple(float(v) for v in bar.GetLookupTable().GetRange())]


def widget_pixels(widget) -> np.ndarray:
    """What ``widget`` paints, as (H, W, 3) uint8: rendered into a 32-bit image (a grab takes the X server's depth,
    16 bits under pytest-xvfb, and rounds colours to RGB565)."""
    from PySide6.QtGui import QImage

    image = QImage(widget.size(), QImage.Format.Format_RGB32)
    image.fill(0)
    widget.render(image)
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    data = np.frombuffer(image.constBits(), np.uint8, image.sizeInBytes())
    return data.reshape(image.height(), image.bytesPerLine())[:, :3 * image.width()].reshape(image.height(),
                                                                                             image.width(), 3).copy()


def hover(qtbot, widget, pos: QPoint) -> None:
    """The mouse moved (no button held) to ``pos`` over ``widget``, as a real move event."""
    _mouse(widget, QEvent.Type.MouseMove, QPointF(pos), Qt.MouseButton.NoButton, Qt.MouseButton.NoButton)
    qtbot.wait(50)


def click(qtbot, widget, pos: QPoint, double: bool = False) -> None:
    """A left click (press and release at ``pos``; ``double``: then a double click) as real events on ``widget``."""
    left = Qt.MouseButton.LeftButton
    _mouse(widget, QEvent.Type.MouseButtonPress, QPointF(pos), left, left)
    _mouse(widget, QEvent.Type.MouseButtonRelease, QPointF(pos), Qt.MouseButton.NoButton, left)
    if double:
        _mouse(widget, QEvent.Type.MouseButtonDblClick, QPointF(pos), left, left)
        _mouse(widget, QEvent.Type.MouseButtonRelease, QPointF(pos), Qt.MouseButton.NoButton, left)
    qtbot.wait(50)


def open_and_show_dock(qtbot, window, path, dock) -> np.ndarray:
    """Open ``path``, wait for its final picture, bring ``dock`` to the front; returns the screen before any edit."""
    window.open_path(path)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    shown = screen(window)
    dock.show()
    dock.raise_()
    qtbot.waitUntil(dock.widget().isVisible)
    return shown


def changed_share(a: np.ndarray, b: np.ndarray, levels: float = 8.0) -> float:
    """The fraction of pixels of two frames that differ by more than ``levels`` (8-bit units) in a channel."""
    return float((np.abs(a - b).max(axis=2) > levels).mean())
