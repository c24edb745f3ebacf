"""A slice plane held and moved (dragged in the 3D view, or by its slider with the mouse) over a regular volume: the
frames of the moves at VTK's interactive rate, the still frame once the plane is let go (issue #28,
docs/bench/flow-gaps.md: each move was a still frame, its ray cast holding the event loop 150-330 ms at the
window's size on this machine, where the interactive rate takes 19-40 ms). The picture the user is left with is
``volviz render``'s."""
from __future__ import annotations

from PySide6.QtCore import QPoint
from PySide6.QtWidgets import QStyle, QStyleOptionSlider

from flows import assert_matches_render, drag, wait_settled
from test_flow_slices import K, _on_screen, z_plane_shown


def _rates_of(window, move) -> list[float]:
    """The desired update rate of each render ``move()`` and what follows it until the window settles cause."""
    ren_win = window.plotter.ren_win
    rates: list[float] = []
    tag = ren_win.AddObserver("StartEvent", lambda *args: rates.append(ren_win.GetDesiredUpdateRate()))
    try:
        move()
        wait_settled(window.qtbot, window)
    finally:
        ren_win.RemoveObserver(tag)
    return rates


def _assert_previews_then_still(window, rates: list[float]) -> None:
    still = window.plotter.iren.interactor.GetStillUpdateRate()
    assert sum(rate > 1.0 for rate in rates) >= 3, rates        # the moves' frames (before: all at the still rate)
    assert rates[-1] == still and window.plotter.ren_win.GetDesiredUpdateRate() == still, rates   # let go


def test_a_plane_dragged_in_the_3d_view_moves_at_the_interactive_rate(qtbot, make_window, tmp_path) -> None:
    window, dock = z_plane_shown(qtbot, make_window)
    window.qtbot = qtbot
    volume = window.controller.dataset_of("data")
    canvas = window.plotter.interactor
    ratio = canvas.devicePixelRatioF()

    def on_screen(k: float) -> QPoint:
        x, y = _on_screen(window, volume, (volume.dimensions[0] - 1) / 2, (volume.dimensions[1] - 1) / 2, k)
        return QPoint(round(x / ratio), round(y / ratio))

    rates = _rates_of(window, lambda: drag(qtbot, canvas, on_screen(0), on_screen(K), steps=12))
    assert dock.spins["z"].value() == K
    _assert_previews_then_still(window, rates)
    assert_matches_render(window, tmp_path, "slice-drag")


def test_a_slider_dragged_with_the_mouse_moves_its_plane_at_the_interactive_rate(qtbot, make_window,
                                                                                 tmp_path) -> None:
    window, dock = z_plane_shown(qtbot, make_window)
    window.qtbot = qtbot
    slider = dock.sliders["z"]
    option = QStyleOptionSlider()
    slider.initStyleOption(option)
    handle = slider.style().subControlRect(QStyle.ComplexControl.CC_Slider, option,
                                           QStyle.SubControl.SC_SliderHandle, slider)
    groove = slider.style().subControlRect(QStyle.ComplexControl.CC_Slider, option,
                                           QStyle.SubControl.SC_SliderGroove, slider)
    start = handle.center()
    end = QPoint(start.x() + (groove.width() - handle.width()) // 2, start.y())   # about the middle of the range

    rates = _rates_of(window, lambda: drag(qtbot, slider, start, end, steps=10))
    index = dock.spins["z"].value()
    assert 0 < index < slider.maximum() and not slider.isSliderDown()
    comp = next(c for c in window.controller.session.components if c.type == "slices")
    assert comp.settings == {"z": index} and window.controller.views[comp.id].indices == {"z": index}
    _assert_previews_then_still(window, rates)
    assert_matches_render(window, tmp_path, "slider-drag")
    window.action_undo.trigger()                # the moves are one undo step
    assert comp.settings == {"z": 0} and dock.spins["z"].value() == 0
