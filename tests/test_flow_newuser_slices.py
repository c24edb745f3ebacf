"""A new user's flow on a file the other flow tests do not open (issue #28, "try it as a new user would"): the
hydrogen atom (``volumes/hydrogen.vti``, float32 64³), an X slice checked in the Slices dock and its slider moved ten
steps with the arrow key, as fast as the keys repeat.

Found by driving the window so: the steps come while the scene is rebuilt with its new slices component, each one
supersedes the rebuild before it, and the window kept the handler of every superseded job (the runner never calls
it), so ``window.jobs.busy()`` stayed True for good (no flow could tell the view had settled) and each kept handler
held on to the scene it was made for. Bound on the picture: as the other
flow tests, the same scene drawn by the same renderers at the same camera and size (RMSE < 1.5, under 0.2 % of the
pixels off by more than 24 levels)."""
from __future__ import annotations

import json

from PySide6.QtCore import QPoint, Qt

from conftest import data_file
from flows import compare_with_render, open_and_show_dock, wait_loaded, wait_settled

STEPS = 10


def test_a_slice_slider_moved_fast_settles_at_the_picture_volviz_renders(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    open_and_show_dock(qtbot, window, data_file("volumes/hydrogen.vti"), window.slices_dock)
    dock = window.slice_tool.dock
    check = dock.checks["x"]
    qtbot.mouseClick(check, Qt.MouseButton.LeftButton, pos=QPoint(8, check.height() // 2))
    slider = dock.sliders["x"]     # at once, while the scene is rebuilt with its slices component
    slider.setFocus()
    for _ in range(STEPS):
        qtbot.keyClick(slider, Qt.Key.Key_Right)

    def slices() -> list[dict]:
        return [c.settings for c in window.controller.session.components if c.type == "slices"]

    qtbot.waitUntil(lambda: slices() == [{"x": STEPS}], timeout=30000)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window, timeout=60000)   # before the fix: never (the superseded jobs' handlers stayed)
    assert not window.jobs.busy()
    assert dock.views["x"].image is not None and dock.views["y"].image is None
    err = compare_with_render(window, tmp_path, "slice")
    saved = json.loads((tmp_path / "slice.json").read_text())
    assert [c["settings"] for c in saved["components"] if c["type"] == "slices"] == [{"x": STEPS}]
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err
