"""A constant field's transfer function is drawn across the TF dock (issue #28, found driving the app as a new user):
Fluent's room case, Array -> SV_BF_V:0 (0 everywhere): the first transfer function spans 0 +- 1e-6, but the
histogram's range was 0 .. 1, so the dock drew every control point on the canvas's left edge (nothing to drag
apart) and its color bar in the last point's red, while the scalar bar showed the whole ramp."""
from __future__ import annotations

import numpy as np

from flows import assert_matches_render, open_settled, pick_combo_item, wait_settled, widget_pixels
from volviz_app.docks.tf_canvas import COLOR_BAR_HEIGHT, MARGIN


def test_the_tf_dock_spreads_a_constant_fields_points_over_its_width(qtbot, make_window, tmp_path) -> None:
    """room.cas.h5, the array SV_BF_V:0 picked in the Scene dock: the TF dock's first and last control points sit at
    the canvas's plot edges, its color bar runs from the first point's color to the last's, and the viewport
    matches ``volviz render`` of the saved session."""
    window = open_settled(qtbot, make_window, "ecosystem/fluent-room/room.cas.h5")
    window.scene_dock.raise_()
    pick_combo_item(qtbot, window.scene_tree.array, "SV_BF_V:0")
    qtbot.waitUntil(lambda: window.tf_editor.info.text().startswith("data: 5 points, range -1e-06"), timeout=60000)
    wait_settled(qtbot, window)
    canvas = window.tf_editor.canvas
    qtbot.waitUntil(lambda: canvas.histogram is not None, timeout=30000)
    plot = canvas._plot_rect()
    xs = [canvas.to_screen(float(s), 0.0).x() for s in canvas.scalars]
    assert abs(xs[0] - plot.left()) < 1 and abs(xs[-1] - plot.right()) < 1, (xs, plot)   # before: all at the left
    assert np.all(np.diff(xs) > 20), xs
    pixels = widget_pixels(canvas).astype(int)
    row = int(plot.bottom() + MARGIN + COLOR_BAR_HEIGHT / 2)      # the middle of the color bar under the plot
    ends = pixels[row, [int(plot.left()) + 1, int(plot.right()) - 2]]
    colors = np.rint(np.clip(canvas.colors[[0, -1]], 0, 1) * 255).astype(int)
    assert np.abs(ends - colors).max() <= 8, (ends, colors)      # before: red at both ends
    assert_matches_render(window, tmp_path, "constant", max_rmse=1.0, max_off=0.002)
