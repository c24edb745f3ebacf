"""A click on a control point of the transfer-function canvas takes that point, not a neighbour in reach (issue #28:
with the 33-point 'hot' preset in a short canvas, a drag of one point moved the point before it, because the pick
took the first point within reach of the click)."""
from __future__ import annotations

from volviz.optics.presets import load_preset
from volviz_app.docks.tf_canvas import MIN_HEIGHT, TransferFunctionCanvas


def test_a_click_on_each_point_of_a_dense_function_picks_that_point(qtbot) -> None:
    canvas = TransferFunctionCanvas()
    qtbot.addWidget(canvas)
    canvas.resize(338, MIN_HEIGHT)
    hot = load_preset("hot").rescaled(0.0, 255.0)
    canvas.scalars, canvas.colors, canvas.extinction = hot.scalars.copy(), hot.colors.copy(), hot.extinction.copy()
    picked = [canvas.point_at(canvas.to_screen(float(s), float(r))) for s, r in zip(hot.scalars, hot.extinction)]
    assert picked == list(range(len(hot.scalars)))
