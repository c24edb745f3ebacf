"""The native-window viewport (issue #28, ``app/native_viewport.py``) in the test process: the default on X11 only,
pyvistaqt's with ``VOLVIZ_VIEWPORT=qt``; a file dropped on it opens,
VTK's cursor changes reach the widget, and closing the window lets VTK's render window go, and with it the X
connection VTK opened to load GLX, so a test run whose X server stops before the process exits (pytest-xvfb's) still
exits with status 0. Before, Xlib's fatal I/O error on that connection at exit made the run's exit status 1 although
every test passed."""
from __future__ import annotations

import gc
import os
import subprocess
import sys
import weakref
from pathlib import Path

import pytest

from conftest import data_file
from test_app_open import drop
from test_app_window import wait_loaded
from test_fly_reduced_frames import test_frames_while_flying_are_drawn_at_half_size as flight


def _sockets() -> int:
    """The process's open sockets (its X connections among them)."""
    fds = Path("/proc/self/fd")
    return sum(os.readlink(fd).startswith("socket:") for fd in fds.iterdir() if fd.exists())


@pytest.fixture
def native(monkeypatch: pytest.MonkeyPatch) -> None:
    """The windows made from now on have the native viewport (X11 only)."""
    from PySide6.QtWidgets import QApplication

    if QApplication.platformName() != "xcb":
        pytest.skip(f"the native viewport needs X11, the platform is {QApplication.platformName()}")
    monkeypatch.setenv("VOLVIZ_VIEWPORT", "native")


def test_the_viewport_is_native_on_x11_unless_the_setting_says_qt(caplog: pytest.LogCaptureFixture) -> None:
    from volviz_app.viewport_types import viewport_kind

    assert [viewport_kind("xcb", setting) for setting in ("", "native", "qt")] == ["native", "native", "qt"]
    for platform in ("wayland", "offscreen", "windows", "cocoa"):   # a native GLX window needs X11
        assert [viewport_kind(platform, setting) for setting in ("", "native", "qt")] == ["qt", "qt", "qt"]
    assert viewport_kind("xcb", "qtt") == "native" and "VOLVIZ_VIEWPORT='qtt'" in caplog.text


def test_the_qt_setting_gives_pyvistaqts_viewport_and_its_reduced_frames(qtbot, make_window, tmp_path: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """The opt-out (and the viewport off X11) keeps its own reduced frames (the render window resized at each
    paint's render): ``test_fly_reduced_frames``' flight in pyvistaqt's widget."""
    from pyvistaqt import QtInteractor

    monkeypatch.setenv("VOLVIZ_VIEWPORT", "qt")
    made = []

    def make():
        made.append(make_window())
        return made[-1]

    flight(qtbot, make, tmp_path)
    assert [type(window.plotter) for window in made] == [QtInteractor]


def test_a_file_dropped_on_the_native_viewport_opens(qtbot, make_window, native: None) -> None:
    from PySide6.QtCore import Qt
    from vtkmodules.vtkCommonCore import VTK_CURSOR_HAND

    window = make_window()
    assert type(window.plotter).__name__ == "NativeViewport"
    hydrogen = data_file("volumes/hydrogen.vti")
    assert drop(window.plotter.interactor, [hydrogen])   # taken by the window's FileDrop, not VTK's widget
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: "hydrogen.vti" in window.windowTitle())
    assert window.session.datasets[0].path == str(hydrogen.resolve())
    window.plotter.GetRenderWindow().SetCurrentCursor(VTK_CURSOR_HAND)   # as a VTK widget under the mouse does
    qtbot.waitUntil(lambda: window.plotter.interactor.cursor().shape() == Qt.CursorShape.PointingHandCursor)


def test_native_window_closes_in_process(make_window, native: None) -> None:
    before = _sockets()
    window = make_window()
    assert type(window.plotter).__name__ == "NativeViewport"
    render_window = weakref.ref(window.plotter.GetRenderWindow())
    assert render_window().GetClassName() == "vtkXOpenGLRenderWindow"
    window.plotter.render()
    assert _sockets() > before                      # VTK's own X connections while the viewport is open
    window.dirty = False
    window.close()
    gc.collect()
    assert render_window() is None                  # nothing holds the closed viewport's render window ...
    assert _sockets() == before                     # ... and VTK's X connections are closed


def test_a_run_that_closed_a_native_window_exits_cleanly(tmp_path: Path) -> None:
    """The test above alone in its own pytest run under its own Xvfb: pytest's exit status is 0."""
    node = f"{Path(__file__).name}::test_native_window_closes_in_process"
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_XDIST", "PYTEST_CURRENT"))}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-n", "0", "-p", "no:cacheprovider", "-q", node],
                          cwd=Path(__file__).parent, env=dict(env, QT_QPA_PLATFORM="xcb"),
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "1 passed" in proc.stdout
