"""Issue #28's Python console dock in the real window: opened from View > Python Console, it runs code in the app's
own process with the session, its scene controller and volviz in scope; the scope follows a newly opened scene; the
kernel stops with the window; without qtconsole the dock says how to install it."""
from __future__ import annotations

import builtins
import os
import sys

from conftest import data_file
from flows import wait_loaded, wait_settled


def _open(qtbot, window, relative: str) -> None:
    window.open_path(data_file(relative))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)


def _run(qtbot, console, code: str, expected: str) -> str:
    """Execute ``code`` in the console as if typed and Enter pressed; wait until its output shows ``expected``."""
    control = console.widget._control        # the console's text area: what the user reads
    shown = control.toPlainText()
    console.widget.execute(code)
    qtbot.waitUntil(lambda: expected in control.toPlainText()[len(shown):], timeout=20000)
    return control.toPlainText()[len(shown):]


def test_console_has_the_session_in_scope_and_stops_with_the_window(qtbot, make_window) -> None:
    """neghip: View > Python Console; ``print(session.components[0].id)`` prints the component's id, the camera the
    console reads is the window's, ``np`` and ``volviz`` are there; after opening hydrogen.vti the console's
    ``session`` is the new one; closing the window stops the kernel and takes IPython's names out of builtins."""
    from ipykernel.inprocess.ipkernel import InProcessInteractiveShell

    window = make_window()
    _open(qtbot, window, "volumes/neghip.slc")
    console = window.python_console
    assert console.dock is None                  # nothing started before it is asked for
    env = {name: os.environ.get(name) for name in ("PAGER", "FORCE_COLOR", "CLICOLOR", "TERM")}
    window.python_console.action.trigger()       # View > Python Console
    qtbot.waitUntil(lambda: console.dock is not None and console.widget is not None and console.widget.isVisible())
    assert {name: os.environ.get(name) for name in env} == env   # the shell's pager settings stay in the shell
    comp_id = window.session.components[0].id
    out = _run(qtbot, console, "print(session.components[0].id)", f"\n{comp_id}\n")
    assert f"print(session.components[0].id)\n{comp_id}\n" in out, out

    cam = window.controller.camera()
    expected = " ".join(f"{v:.4f}" for v in (*cam.position, *cam.focal_point))
    code = "c = controller.camera(); print('CAM', *(f'{v:.4f}' for v in (*c.position, *c.focal_point)))"
    out = _run(qtbot, console, code, "CAM ")
    assert f"\nCAM {expected}\n" in out, (out, expected)
    out = _run(qtbot, console, "print('VER', volviz.__name__, np.arange(3).sum(), window is not None)", "VER ")
    assert "\nVER volviz 3 True\n" in out, out

    _open(qtbot, window, "volumes/hydrogen.vti")   # a new scene: the console's names follow it
    new_path = str(window.session.datasets[0].path)
    assert "hydrogen" in new_path
    out = _run(qtbot, console, "print('DATA', session.datasets[0].path)", "DATA ")
    assert f"\nDATA {new_path}\n" in out, out

    shell = console.manager.kernel.shell
    window.dirty = False
    window.close()
    assert console.manager is None and not InProcessInteractiveShell.initialized()
    assert "window" not in shell.user_ns and "session" not in shell.user_ns   # the window is not held by the shell
    assert not hasattr(builtins, "__IPYTHON__") and not hasattr(builtins, "get_ipython")


def test_console_without_qtconsole_says_how_to_install_it(qtbot, make_window, monkeypatch) -> None:
    """qtconsole not importable (as in the packaged app, which leaves it out): View > Python Console opens a dock
    whose one line says to ``pip install 'volviz[console]'``; the status bar says it too."""
    from volviz_app.console import MISSING

    for name in ("qtconsole", "qtconsole.inprocess", "qtconsole.rich_jupyter_widget"):
        monkeypatch.setitem(sys.modules, name, None)     # an import of it raises ImportError, as when absent
    window = make_window()
    window.python_console.action.trigger()
    console = window.python_console
    qtbot.waitUntil(lambda: console.dock is not None and console.dock.isVisible())
    assert console.widget is None and console.dock.widget() is console.message
    assert console.message.text() == MISSING and "pip install 'volviz[console]'" in MISSING and "\n" not in MISSING
    assert window.status_label.text() == MISSING


_FRESH_WINDOW = """
import sys
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QApplication
app = QApplication([])
from volviz_app.console import PRELOADED
from volviz_app.window import MainWindow
window = MainWindow(settings=QSettings(sys.argv[1], QSettings.Format.IniFormat), recovery_dir=sys.argv[2])
window.show()
for _ in range(3000):
    app.processEvents()
    if all(name in sys.modules for name in PRELOADED):
        break
    import time; time.sleep(0.01)
print("loaded" if all(name in sys.modules for name in PRELOADED) else "missing",
      "started" if window.python_console.dock is not None else "not started")
window.dirty = False
window.close()
"""


def test_the_consoles_modules_are_imported_in_the_background_before_it_is_first_opened(tmp_path) -> None:
    """A new window imports what the console's first opening needs (``console.PRELOADED``) on a thread of its own,
    without starting it: on the GUI thread that opening held the event loop 404 ms (320 ms of imports, 37 ms of
    the Python lexer's rules), now 33 ms. In a fresh process, as a user's first start (this test process has
    imported them already)."""
    import subprocess

    run = subprocess.run([sys.executable, "-c", _FRESH_WINDOW, str(tmp_path / "s.ini"), str(tmp_path / "rec")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.split() == ["loaded", "not", "started"], run.stdout + run.stderr[-2000:]
