"""File > Show Another Array or Series… in the real window under Xvfb (``volviz_app.file_choices``): an HDF5 file of
two volumes opens on the larger, the action is enabled and its dialog lists both with the shown one selected;
picking the other loads it (its own dimensions and values), sets the dataset's reader option in the session (saved
with it) and keeps the action for going back. A file with one volume leaves the action off."""
from __future__ import annotations

import json

import h5py
import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from test_app_workflows import wait_loaded


def _two_volumes(path):
    with h5py.File(path, "w") as f:
        f["large"] = np.random.default_rng(0).random((12, 14, 16)).astype(np.float32)
        f["small"] = np.arange(5 * 6 * 7, dtype=np.float32).reshape(5, 6, 7)
    return path


def test_pick_another_dataset_of_an_hdf5_file(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    window.resize(720, 540)
    path = _two_volumes(tmp_path / "scan.h5")
    window.open_path(path)
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: window.file_choices.action.isEnabled(), timeout=30000)
    assert window.datasets["data"].dimensions == (16, 14, 12)            # the larger, laid out x, y, z
    assert "holds 2 arrays" in window.status_label.toolTip()
    assert "2 datasets: Ctrl+Alt+A shows another" in window.status_label.text()

    window.file_choices.action.trigger()
    dialog = window.file_choices.dialog
    assert dialog is not None and dialog.isVisible()
    labels = [dialog.list.item(i).text() for i in range(dialog.list.count())]
    assert labels == ["/large (12x14x16)", "/small (5x6x7)"]
    assert dialog.list.currentItem().text() == "/large (12x14x16)"
    qtbot.mouseClick(dialog.list.viewport(), Qt.MouseButton.LeftButton,
                     pos=dialog.list.visualItemRect(dialog.list.item(1)).center())
    assert dialog.picked() == "/small"
    qtbot.mouseClick(dialog.findChild(QDialogButtonBox).button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.datasets.get("data") is not None
                    and window.datasets["data"].dimensions == (7, 6, 5), timeout=60000)
    wait_loaded(qtbot, window)
    shown = window.datasets["data"]
    np.testing.assert_array_equal(np.asarray(shown.data).ravel(order="F"), np.arange(5 * 6 * 7))
    assert window.session.datasets[0].options == {"dataset": "/small"} and window.dirty
    # saved with the session, and the way back stays open
    qtbot.waitUntil(lambda: window.file_choices.action.isEnabled(), timeout=30000)
    assert window.file_choices.choices[0].chosen == "/small"
    from volviz.session import session_to_dict

    stored = json.loads(json.dumps(session_to_dict(window.session)))
    assert stored["datasets"][0]["options"] == {"dataset": "/small"}


def test_a_file_with_one_volume_has_nothing_to_choose(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    window.resize(720, 540)
    path = tmp_path / "one.h5"
    with h5py.File(path, "w") as f:
        f["only"] = np.ones((4, 5, 6), np.float32)
    window.open_path(path)
    wait_loaded(qtbot, window)
    qtbot.wait(200)
    assert not window.file_choices.action.isEnabled() and window.file_choices.choices == []


def test_pick_another_orbital_of_a_cube_file(qtbot, make_window, tmp_path) -> None:
    """An option that takes integers (a cube file's orbital numbers) goes to the reader as an integer."""
    from test_io_imaging import _as_written, _cube_file

    window = make_window()
    window.resize(720, 540)
    values = _as_written(np.random.default_rng(8).normal(size=(3, 4, 5, 2)))
    path = _cube_file(tmp_path / "mo.cube", values, (0, 0, 0), ((0.2, 0, 0), (0, 0.2, 0), (0, 0, 0.2)),
                      orbitals=[12, 13])
    window.open_path(path)
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: window.file_choices.action.isEnabled(), timeout=30000)
    assert window.datasets["data"].name == "orbital 12"
    assert "2 orbitals: Ctrl+Alt+A shows another" in window.status_label.text()
    window.file_choices.action.trigger()
    dialog = window.file_choices.dialog
    assert [dialog.list.item(i).text() for i in range(dialog.list.count())] == ["orbital 12", "orbital 13"]
    dialog.list.setCurrentRow(1)
    qtbot.mouseClick(dialog.findChild(QDialogButtonBox).button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.datasets.get("data") is not None
                    and window.datasets["data"].name == "orbital 13", timeout=60000)
    assert window.session.datasets[0].options == {"orbital": 13}
    np.testing.assert_array_equal(window.datasets["data"].data, values[..., 1])
