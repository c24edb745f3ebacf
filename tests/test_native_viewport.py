"""The native-window viewport, the default on X11 (issue #28, ``app/native_viewport.py``): a Yukon flight in the real
window, run in its own process. The flight's frames are drawn reduced by the native widget's own paint, the picture
left after the stop is ``volviz render``'s, what X shows in the viewport's window is that picture, the window's
``grab()`` shows it too, and the process closes its window and exits cleanly."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from conftest import data_file
from flows import render_saved
from volviz.optics.metrics import rmse

# In the subprocess: fly the Yukon session 3 s with W held (flight_report.fly), wait for the still full-size frame,
# then save the session, the plotter's screenshot, what X shows in the viewport's window and the window's grab().
SCRIPT = r"""
import json, sys
from pathlib import Path
import numpy as np
import imageio.v3 as iio
from PySide6.QtCore import QPoint, QSettings
from PySide6.QtWidgets import QApplication
from volviz_app import flight_report
from volviz_app.smoke import pump_events
from volviz_app.window import MainWindow

def rgb(image):
    image = image.convertToFormat(image.Format.Format_RGB888)
    bits = np.frombuffer(image.constBits(), np.uint8).reshape(image.height(), image.bytesPerLine())
    return bits[:, :image.width() * 3].reshape(image.height(), image.width(), 3)

out = Path(sys.argv[1])
app = QApplication(sys.argv[:1])
window = MainWindow(settings=QSettings(str(out / "settings.ini"), QSettings.Format.IniFormat),
                    recovery_dir=out / "recovery")
result = flight_report.fly(app, window, None, 3.0)
(out / "report.md").write_text(flight_report.markdown(result, "test_native_viewport"))
settled = pump_events(app, lambda: not window.jobs.busy() and not window.fly.frames.active
                      and window.controller.nature.shown_scale == 1, 180.0)
pump_events(app, lambda: False, 1.0)
assert window.save_session(out / "still.json")
window.plotter.render()
shot = np.asarray(window.plotter.screenshot(None, return_img=True))[..., :3]
iio.imwrite(out / "still.png", shot)
canvas = window.plotter.interactor
iio.imwrite(out / "x_window.png", rgb(app.primaryScreen().grabWindow(canvas.winId()).toImage()))
corner, screen = canvas.mapToGlobal(QPoint(0, 0)), app.primaryScreen().geometry()   # X keeps no pixels off screen
visible = [min(shot.shape[1], screen.right() + 1 - corner.x()), min(shot.shape[0], screen.bottom() + 1 - corner.y())]
at = canvas.mapTo(window, QPoint(0, 0))
grab = rgb(window.grab().toImage())[at.y():at.y() + shot.shape[0], at.x():at.x() + shot.shape[1]]
iio.imwrite(out / "grab.png", np.ascontiguousarray(grab))
result.update(settled=settled, visible=visible, platform=app.platformName(),
              ren_win=window.plotter.ren_win.GetClassName())
(out / "result.json").write_text(json.dumps(result))
window.dirty = False
window.close()
print("closed")
"""


def _same_frame(a: np.ndarray, b: np.ndarray) -> None:
    """``a`` shows the frame ``b`` as a screen of pytest-xvfb's 16-bit depth does (5-6-5 bits: up to 7 levels off
    per channel, RMSE 2.7 measured); a garbage or black viewport is 80 or more off."""
    rms, off = _rmse(a, b), float((np.abs(a.astype(np.float64) - b).max(axis=2) > 24).mean())
    assert rms < 4.0 and off < 0.001, (rms, off)


def _rmse(a: np.ndarray, b: np.ndarray) -> float:
    """RMSE in 8-bit units, as ``flows.compare_with_render``."""
    assert a.shape == b.shape, (a.shape, b.shape)
    return rmse(np.asarray(a, np.float64) / 255.0, np.asarray(b, np.float64) / 255.0)


def test_native_viewport_flight_in_a_subprocess(tmp_path: Path) -> None:
    data_file("yukon/Yukon.map.pgm")
    env = {name: value for name, value in os.environ.items() if name != "VOLVIZ_VIEWPORT"}   # the default
    env["QT_QPA_PLATFORM"] = "xcb"
    proc = subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path)], env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]   # a clean close of the GLX window
    assert proc.stdout.rstrip().endswith("closed")
    result = json.loads((tmp_path / "result.json").read_text())
    report = (tmp_path / "report.md").read_text()
    print(report)

    assert result["platform"] == "xcb"
    assert result["viewport_class"] == "NativeViewport"            # the default on X11 ...
    assert result["ren_win"] == "vtkXOpenGLRenderWindow"           # ... and VTK draws into its own X window
    assert "(NativeViewport)" in report
    w, h = (int(v) for v in result["viewport"].split("x"))
    assert result["reduced_frames"] > 0                               # frames drawn reduced while flying ...
    assert result["reduced_size"] == f"{-(-w // 2)}x{-(-h // 2)}"     # ... at half the viewport in each direction
    assert result["frames"] >= result["reduced_frames"] and result["steps"] > 0
    assert result["settled"]

    still = np.asarray(iio.imread(tmp_path / "still.png"))[..., :3]
    assert still.shape == (h, w, 3)                                   # the render window back at its full size
    ref = render_saved(tmp_path / "still.json", (w, h), tmp_path / "reference.png")
    error, off = _rmse(still, ref), float((np.abs(still - ref).max(axis=2) > 24).mean())
    assert error < 2.0 and off < 0.01, (error, off)   # flows.assert_matches_render's bounds
    shown = np.asarray(iio.imread(tmp_path / "x_window.png"))[..., :3]
    vw, vh = result["visible"]                 # the viewport's part on the X screen (pytest-xvfb's is 800x600)
    assert vw * vh >= 0.5 * w * h, result["visible"]
    _same_frame(shown[:vh, :vw], still[:vh, :vw])                     # what X shows is that frame
    grab = np.asarray(iio.imread(tmp_path / "grab.png"))[..., :3]
    _same_frame(grab, still)                                          # and the window's grab() shows it
