"""The value under a resting cursor follows the data shown (issue #28, found driving the app as a new user): the
probe answered only mouse moves, so after the display time changed (a time step taken with the keyboard, playback)
or the scene was replaced (another file opened from the keyboard) the status bar kept naming the value of data no
longer shown (hydrogen's "value 0.006982 at (44, 42, 50)" stayed over the iron protein opened after it)."""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt

from conftest import data_file
from flows import wait_settled
from test_flow_probe import _open, _probe_centre


def test_a_time_step_taken_with_the_keyboard_probes_the_resting_cursor_again(qtbot, make_window) -> None:
    """Storm, the cursor resting over the core of its 4th step while the first is shown; three steps on with the
    Space key on the timeline's focused ▶ button: the status bar names the value of the voxel under the cursor in
    the frame shown."""
    from volviz.model.timeseries import frame_at

    window = _open(qtbot, make_window, data_file("storm/Storm.pvm-t01"))
    controller = window.controller
    series = next(iter(controller.time_series().values()))
    later = series.frame(3)
    core = np.unravel_index(np.argmax(later.data), later.data.shape)
    before, _, _ = _probe_centre(qtbot, window, np.asarray(later.origin) + np.asarray(core) * np.asarray(later.spacing))
    start = controller.time
    first = frame_at(series, start, controller.interpolate_time)
    assert before.value == float(first.data[before.voxel])
    button = window.timeline.forward_button
    button.setFocus()
    for _ in range(3):
        qtbot.keyClick(button, Qt.Key.Key_Space)
    wait_settled(qtbot, window)
    shown = frame_at(series, controller.time, controller.interpolate_time)
    assert controller.time == start + 3 * (series.times[1] - series.times[0])
    qtbot.waitUntil(lambda: window.probe.last is not before, timeout=5000)   # before the fix: never
    hit = window.probe.last
    assert hit.value == float(shown.data[hit.voxel])   # the first visible voxel on the ray in the frame shown
    assert window.probe.label.text() == f"Probe: {hit.text()}"


def test_a_new_file_opened_under_the_resting_cursor_replaces_the_old_value(qtbot, make_window) -> None:
    """hydrogen.vti probed at the viewport's centre, then ironProt.vtk opened (as File > Open Recent from the
    keyboard does): the status bar names ironProt's voxel under the cursor, not hydrogen's."""
    window = _open(qtbot, make_window, data_file("volumes/hydrogen.vti"))
    first, _, _ = _probe_centre(qtbot, window)
    window.open_path(data_file("volumes/ironProt.vtk"))
    wait_settled(qtbot, window)
    assert window.windowTitle().endswith("ironProt.vtk")
    qtbot.waitUntil(lambda: window.probe.last is not first, timeout=5000)       # before the fix: never
    hit = window.probe.last
    text = window.probe.label.text()
    assert text in ("Probe: nothing visible under the cursor", f"Probe: {hit.text() if hit else ''}"), text
    if hit is not None:
        volume = window.datasets["data"]
        assert hit.value == float(volume.data[hit.voxel])
