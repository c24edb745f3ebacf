"""The scene tree's array selector under Xvfb: switching the array a component shows is one undoable step and is
saved with the session."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from conftest import data_file
from test_app_window import viewport_image, wait_loaded, window  # noqa: F401  (the fixture)
from volviz_app.window import MainWindow


def shown_array(window: MainWindow) -> object:
    return window.controller.component("data").settings.get("array")


def test_switch_array_undo_and_save(qtbot, window: MainWindow, tmp_path: Path) -> None:
    from volviz.model.arrays import list_arrays
    from volviz.session import load

    window.open_path(data_file("ecosystem/notch_disp.vtu"))
    wait_loaded(qtbot, window)
    assert window.error_dialog is None, window.error_dialog.text()
    combo = window.scene_tree.array
    choices = [combo.itemData(i) for i in range(combo.count())]
    assert choices == [c for info in list_arrays(window.datasets["data"]) for c in info.choices]
    assert combo.isEnabled() and combo.currentText() == "Nodal Displacement:magnitude"
    before, props_before = viewport_image(window), list(window.controller.props.values())

    index = combo.findData("Nodal Displacement:1")
    combo.setCurrentIndex(index)
    combo.activated.emit(index)  # what a user's pick sends
    qtbot.waitUntil(lambda: shown_array(window) == "Nodal Displacement:1")
    wait_loaded(qtbot, window)
    assert list(window.controller.props.values()) != props_before  # the component was prepared again
    assert combo.currentText() == "Nodal Displacement:1"
    switched = viewport_image(window)
    edges = window.controller.histograms["data"][1]  # of the data the component shows now: component 1
    assert edges[0] < -1e-7 * 0.9 and edges[-1] < 2e-7
    assert np.abs(switched.astype(int) - before.astype(int)).max() > 30  # another array, another image
    assert window.dirty

    window.action_undo.trigger()
    qtbot.waitUntil(lambda: shown_array(window) is None)
    wait_loaded(qtbot, window)
    assert combo.currentText() == "Nodal Displacement:magnitude"
    assert np.abs(viewport_image(window).astype(int) - before.astype(int)).max() <= 3

    window.action_redo.trigger()
    qtbot.waitUntil(lambda: shown_array(window) == "Nodal Displacement:1")
    wait_loaded(qtbot, window)
    session_file = tmp_path / "notch.json"
    assert window.save_session(session_file)
    assert load(session_file).components[0].settings["array"] == "Nodal Displacement:1"
    window.open_path(session_file)
    wait_loaded(qtbot, window)
    assert combo.currentText() == "Nodal Displacement:1"
    assert np.abs(viewport_image(window).astype(int) - switched.astype(int)).max() <= 3
