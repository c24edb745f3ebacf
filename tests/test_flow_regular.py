"""Flows on regular volumes in the real window, held to ``volviz render`` of the saved session (issue #28)."""
from __future__ import annotations

from conftest import data_file
from flows import compare_with_render, drag_viewport, wait_loaded, wait_settled


def test_regular_volume_is_full_quality_after_a_drag(qtbot, make_window, tmp_path) -> None:
    """Opening the embryo and orbiting it once: the frame the user is left with is the full-resolution ray cast of
    the new camera (VTK's smart mapper used to keep the coarse sample distance of the drag: RMSE 20+ and blocks)."""
    window = make_window()
    window.open_path(data_file("volumes/embryo.slc"))
    wait_loaded(qtbot, window)
    before = window.controller.camera()
    drag_viewport(qtbot, window, 200, 0)
    wait_settled(qtbot, window)
    assert window.controller.camera() != before
    err = compare_with_render(window, tmp_path)
    # the same VTK ray caster at the same camera and size: only 8-bit rounding and text anti-aliasing differ
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err
