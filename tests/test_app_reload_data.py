"""File > Reload Data (F5) in the real window under Xvfb: a file rewritten on disk (a solver's next output) is read
again and shown with the view kept — the camera the user turned to, the transfer function, the unsaved state — and
a file that became unreadable leaves the shown scene as it was, with an error message."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from test_app_workflows import wait_loaded


def _write(path, values):
    grid = pv.ImageData(dimensions=(8, 7, 6))
    grid.point_data["density"] = values.astype(np.float32)
    grid.save(path)


def test_reload_reads_the_file_again_and_keeps_the_view(qtbot, make_window, tmp_path) -> None:
    path = tmp_path / "step.vti"
    n = 8 * 7 * 6
    _write(path, np.arange(n))
    window = make_window()
    window.resize(720, 540)
    window.open_path(path)
    wait_loaded(qtbot, window)
    first = window.datasets["data"]
    camera = window.plotter.camera
    camera.azimuth = 35.0
    camera.elevation = 20.0
    window.plotter.render()
    position = np.array(camera.position)
    tf = window.session.transfer_functions.copy()
    dirty = window.dirty
    assert window.reload_data.action.shortcut().toString() == "F5"

    _write(path, 2.0 * np.arange(n))                 # the solver's next output
    window.reload_data.action.trigger()
    qtbot.waitUntil(lambda: window.datasets.get("data") is not first and window.datasets.get("data") is not None,
                    timeout=60000)
    wait_loaded(qtbot, window)
    np.testing.assert_array_equal(np.asarray(window.datasets["data"].data).ravel(order="F"), 2.0 * np.arange(n))
    np.testing.assert_allclose(window.plotter.camera.position, position, rtol=1e-9, atol=1e-9)
    assert window.session.transfer_functions == tf and window.dirty == dirty

    path.write_bytes(b"<VTKFile type=\"ImageData\"> cut short")       # a half-written file
    shown = window.datasets["data"]
    window.reload_data.action.trigger()
    qtbot.waitUntil(lambda: window.error_dialog is not None and window.error_dialog.isVisible(), timeout=60000)
    assert "step.vti" in window.error_dialog.text() + window.error_dialog.informativeText()
    window.error_dialog.close()
    assert window.datasets["data"] is shown and window.controller is not None
