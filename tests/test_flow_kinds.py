"""The first hour's flow on every kind of data, in the real window (issue #28): open, orbit with the mouse, zoom with
the wheel, change what is shown (array, time step or transfer function), clip, save, reopen in a new window; at the
end the frame on screen matches ``volviz render`` of the saved session at the same camera and size, and so does the
reopened window's.

Bound: both sides draw the same scene with the same renderers at the same camera and size, so they differ by 8-bit
rounding, text anti-aliasing and, for volviz's CPU overlays, the up to 1/255 of the 8-bit overlay round trip
(``volviz.render.image_overlay``): RMSE < 1.5 and under 0.5 % of the pixels off by more than 24 levels."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from conftest import blob_vvz, data_file
from flows import compare_with_render, drag_viewport, wait_loaded, wait_settled
from test_app_clipping import ball_session

RMSE, OFF = 1.5, 0.005


def _wheel(window, notches: int) -> None:
    """Zoom with the mouse wheel over the viewport's middle."""
    canvas = window.plotter.interactor
    pos = QPointF(canvas.width() / 2, canvas.height() / 2)
    for _ in range(abs(notches)):
        event = QWheelEvent(pos, canvas.mapToGlobal(pos), QPoint(0, 0), QPoint(0, 120 if notches > 0 else -120),
                            Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase,
                            False)
        QApplication.sendEvent(canvas, event)


def _clip(qtbot, window) -> None:
    window.clip_dock.show()
    qtbot.mouseClick(window.clipping.add_button, Qt.MouseButton.LeftButton)


def _change_time(qtbot, window) -> None:
    for _ in range(3):   # three time steps on
        qtbot.mouseClick(window.timeline.forward_button, Qt.MouseButton.LeftButton)


def _change_tf(qtbot, window) -> None:
    window.tf_editor.apply_preset("viridis")


KINDS = {
    # kind: (what to open, the change a scientist makes)
    "regular": (lambda tmp: data_file("volumes/neghip.slc"), _change_tf),
    "unstructured": (lambda tmp: data_file("bluntfin/bluntfinxyz.bin"), _change_tf),
    "time series": (lambda tmp: data_file("storm/Storm.pvm-t01"), _change_time),
    "compressed LOD volume": (lambda tmp: blob_vvz(tmp / "blob.vvz", 64), _change_tf),
    "isosurfaces": (ball_session, None),
}


@pytest.mark.parametrize("kind", list(KINDS))
def test_first_hour_flow(qtbot, make_window, tmp_path: Path, kind: str) -> None:
    what, change = KINDS[kind]
    window = make_window()
    window.open_path(what(tmp_path))
    wait_loaded(qtbot, window)
    assert window.error_dialog is None, window.error_dialog.text()
    drag_viewport(qtbot, window, 160, 40)
    _wheel(window, 2)
    wait_settled(qtbot, window)
    if change is not None:
        change(qtbot, window)
        wait_settled(qtbot, window)
    _clip(qtbot, window)
    wait_settled(qtbot, window)
    err = compare_with_render(window, tmp_path, "flow")
    assert err["rmse"] < RMSE and err["off"] < OFF, (kind, err)

    again = make_window()
    again.open_path(tmp_path / "flow.json")
    wait_loaded(qtbot, again)
    wait_settled(qtbot, again)
    a, b = again.controller.camera(), window.controller.camera()
    for field in ("position", "focal_point", "view_up"):
        assert np.allclose(getattr(a, field), getattr(b, field), rtol=1e-9, atol=1e-9), field
    err = compare_with_render(again, tmp_path, "reopened")
    assert err["rmse"] < RMSE and err["off"] < OFF, (kind, "reopened", err)
