"""A mouse drag renders the viewport once per move (app/interaction_renders.py), not twice, and renders normally
again once the drag ends."""
from __future__ import annotations

from PySide6.QtCore import QEvent, QPoint, Qt

from conftest import data_file
from test_app_workflows import _mouse, wait_loaded


def test_a_drag_renders_once_per_move(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    renders = []
    window.plotter.ren_win.AddObserver("StartEvent", lambda *args: renders.append(1))
    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    held = Qt.MouseButton.LeftButton
    _mouse(canvas, QEvent.Type.MouseButtonPress, centre, held)
    qtbot.wait(50)
    renders.clear()
    moves = 12
    for k in range(1, moves + 1):
        _mouse(canvas, QEvent.Type.MouseMove, centre + QPoint(5 * k, 0), held)
        qtbot.wait(30)                                  # the repaint of each move happens in this wait
    during = len(renders)
    camera = window.plotter.camera.position
    _mouse(canvas, QEvent.Type.MouseButtonRelease, centre + QPoint(5 * moves, 0), Qt.MouseButton.NoButton)
    qtbot.wait(200)
    assert 1 <= during <= moves + 2, f"{during} renders for {moves} moves"     # twice per move before
    assert window.plotter.iren.interactor.GetEnableRender()                    # back to normal after the drag
    renders.clear()
    window.plotter.iren.interactor.Render()
    assert renders and window.plotter.camera.position == camera
