"""Issue #28's missing tools in the real window: the probe, the log color scale and the scalar bar editor, each
driven by real mouse and keyboard events and, where it changes the picture, held to ``volviz render`` of the saved
session."""
from __future__ import annotations

import re

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt

from conftest import data_file
from flows import click, compare_with_render, hover, wait_loaded, wait_settled


def _open_neghip(qtbot, make_window):
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    return window


def _tick_log_scale(qtbot, window) -> None:
    """Click the selected component's Log color scale box in the scene dock's form, as the user does."""
    qtbot.waitUntil(lambda: window.scene_tree.form is not None and "log_scale" in window.scene_tree.form.rows)
    box = window.scene_tree.form.editor("log_scale")
    window.scene_dock.raise_()
    qtbot.waitUntil(box.isVisible)
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton, pos=QPoint(8, box.height() // 2))   # on the box itself



def test_probe_shows_and_pins_the_value_under_the_cursor(qtbot, make_window) -> None:
    """neghip: the mouse at the viewport's centre; the status bar names a voxel whose value in the dataset's array
    is the value shown, and whose centre projects to the cursor; a click pins it, Clear empties the list."""
    window = _open_neghip(qtbot, make_window)
    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    hover(qtbot, canvas, centre)
    qtbot.waitUntil(lambda: window.probe.label.text().startswith("Probe: data"), timeout=5000)
    text = window.probe.label.text()
    found = re.search(r"value (\S+) at \(([^)]*)\), voxel \((\d+), (\d+), (\d+)\)", text)
    assert found, text
    i, j, k = (int(found.group(n)) for n in (3, 4, 5))
    volume = window.datasets["data"]
    assert float(found.group(1)) == float(volume.data[i, j, k]), (text, volume.data[i, j, k])
    value, extinction = window.controller.transfer_function("data").evaluate(np.array([float(volume.data[i, j, k])]))
    assert extinction[0] > 0, "the probe stopped at a transparent voxel"
    # the voxel is under the cursor: its centre projects within a voxel's width of the pixel
    renderer = window.plotter.renderer
    centre_world = np.asarray(volume.origin) + np.array([i, j, k]) * np.asarray(volume.spacing)
    renderer.SetWorldPoint(*centre_world, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    height = window.plotter.ren_win.GetSize()[1]
    pixel = np.array([centre.x(), height - 1 - centre.y()], dtype=np.float64)
    assert np.hypot(*(np.array([x, y]) - pixel)) < 8.0, (x, y, pixel)
    click(qtbot, canvas, centre)
    assert window.probe.pinned.count() == 1
    assert window.probe.pinned.item(0).text() == text[len("Probe: "):]
    assert window.probe.dock.isVisible()
    qtbot.mouseClick(window.probe.clear_button, Qt.MouseButton.LeftButton)
    assert window.probe.pinned.count() == 0


def test_log_color_scale_is_drawn_saved_and_rendered_the_same(qtbot, make_window, tmp_path) -> None:
    """neghip, the component's Log color scale box ticked: the scalar bar reads log ticks from the smallest positive
    value (1) to 255; the session saves the setting; the screen matches ``volviz render`` of the saved session, and
    differs from the linear picture."""
    import json

    window = _open_neghip(qtbot, make_window)
    linear = compare_with_render(window, tmp_path, "linear")
    assert linear["rmse"] < 1.5, linear
    from flows import screen
    before = screen(window)
    _tick_log_scale(qtbot, window)
    assert window.scene_tree.form.editor("log_scale").isChecked()
    qtbot.waitUntil(lambda: window.controller.component("data").settings.get("log_scale") is True, timeout=20000)
    wait_settled(qtbot, window)
    from volviz.render.decorations import scalar_bar_actor, scalar_bar_title

    bar = scalar_bar_actor(window.plotter)
    assert bar.GetLookupTable().UsingLogScale()
    labels = bar.GetCustomLabels()
    ticks = [labels.GetValue(n) for n in range(labels.GetNumberOfTuples())]
    assert ticks == [1, 2, 5, 10, 20, 50, 100, 255], ticks
    assert scalar_bar_title(window.plotter) == "SLCImage (log)"
    err = compare_with_render(window, tmp_path, "log")
    saved = json.loads((tmp_path / "log.json").read_text())
    assert saved["components"][0]["settings"]["log_scale"] is True
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err
    assert np.sqrt(np.mean((screen(window) - before) ** 2)) > 5.0   # the log scale changed the picture


def test_scalar_bar_edited_by_double_click_is_saved_and_rendered(qtbot, make_window, tmp_path) -> None:
    """neghip: a double click on the scalar bar opens its dialog; title "Density", a fixed range 0 .. 100 and the
    format %.3g typed in; the bar shows them, a bad format is refused in the dialog in one line, and ``volviz
    render`` of the saved session draws the same bar; Edit > Undo puts the data's bar back, Redo the edited one."""
    import json

    from volviz.render.decorations import scalar_bar_actor, scalar_bar_title

    window = _open_neghip(qtbot, make_window)
    canvas = window.plotter.interactor
    bar = scalar_bar_actor(window.plotter)
    lo = bar.GetPositionCoordinate().GetComputedDisplayValue(window.plotter.renderer)
    hi = bar.GetPosition2Coordinate().GetComputedDisplayValue(window.plotter.renderer)
    height = window.plotter.ren_win.GetSize()[1]
    on_bar = QPoint((lo[0] + hi[0]) // 2, height - 1 - (lo[1] + hi[1]) // 2)
    click(qtbot, canvas, on_bar, double=True)
    qtbot.waitUntil(lambda: window.scalar_bar_editor.dialog is not None and window.scalar_bar_editor.dialog.isVisible())
    dialog = window.scalar_bar_editor.dialog
    qtbot.keyClicks(dialog.title, "Density")
    qtbot.mouseClick(dialog.fixed, Qt.MouseButton.LeftButton)
    qtbot.keyClicks(dialog.low, "0")
    qtbot.keyClicks(dialog.high, "100")
    qtbot.keyClicks(dialog.fmt, "%s")
    ok = dialog.buttons.button(dialog.buttons.StandardButton.Ok)
    qtbot.mouseClick(ok, Qt.MouseButton.LeftButton)
    assert dialog.isVisible() and "format" in dialog.error.text(), dialog.error.text()
    dialog.fmt.clear()
    qtbot.keyClicks(dialog.fmt, "%.3g")
    qtbot.mouseClick(ok, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.scalar_bar_editor.dialog is None)
    bar = scalar_bar_actor(window.plotter)
    assert scalar_bar_title(window.plotter) == "Density"
    assert tuple(bar.GetLookupTable().GetRange()) == (0.0, 100.0)
    assert bar.GetLabelFormat() == "%.3g"
    wait_settled(qtbot, window)             # the still frame after the double click's interaction
    err = compare_with_render(window, tmp_path, "bar")
    saved = json.loads((tmp_path / "bar.json").read_text())
    assert saved["render"]["options"]["scalar_bar_style"] == {"title": "Density", "range": [0.0, 100.0],
                                                              "format": "%.3g"}
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err

    assert "Edit the scalar bar" in window.action_undo.text(), window.action_undo.text()
    window.action_undo.trigger()            # the edit is one step on the undo stack
    bar = scalar_bar_actor(window.plotter)
    assert scalar_bar_title(window.plotter) == "SLCImage"
    assert tuple(bar.GetLookupTable().GetRange()) == tuple(window.controller.transfer_function("data").range)
    assert "scalar_bar_style" not in window.session.render.options
    window.action_redo.trigger()
    assert scalar_bar_title(window.plotter) == "Density"
    assert tuple(scalar_bar_actor(window.plotter).GetLookupTable().GetRange()) == (0.0, 100.0)


def test_log_color_scale_puts_the_tf_editor_axis_in_log_and_says_what_it_clamps(qtbot, make_window) -> None:
    """neghip, Log color scale ticked: the TF editor's axis runs in log10 from 1 (its color bar, as painted, shows
    the colors the volume is drawn with at 2, 10, 50 and 200), the status bar says how many voxels are 0 (the scale
    draws them in the color of 1); unticked, the axis is linear again."""
    from flows import widget_pixels
    from volviz.scene.drawn_tf import drawn_tf

    from volviz_app.docks.tf_canvas import COLOR_BAR_HEIGHT, MARGIN

    from volviz.optics.transfer_function import TransferFunction

    window = _open_neghip(qtbot, make_window)
    # stops spread evenly over 0..255, set in the TF editor as one edit: on a linear axis the colours at 2, 10, 50
    # and 200 then differ by far more than 20 levels from a log axis's (the first look's histogram-equalized stops,
    # since 638b48e, sit at 1, 5, 15, 45, 255, almost a log spacing already, which left 19 levels between the two)
    even = TransferFunction([0.0, 64.0, 128.0, 192.0, 255.0],
                            [(0.23, 0.30, 0.75), (0.55, 0.69, 0.94), (0.87, 0.87, 0.87), (0.96, 0.60, 0.48),
                             (0.71, 0.02, 0.15)], [0.0, 0.002, 0.004, 0.006, 0.008], name="even")
    window.tf_editor.edit(even, "Even stops")
    wait_settled(qtbot, window)
    canvas = window.tf_editor.canvas
    assert canvas.log_floor is None
    _tick_log_scale(qtbot, window)
    qtbot.waitUntil(lambda: canvas.log_floor == 1.0, timeout=20000)
    wait_settled(qtbot, window)
    volume = window.datasets["data"]
    zeros = int(np.count_nonzero(volume.data <= 0))
    assert zeros > 0
    assert window.statusBar().currentMessage() == (f"{zeros:,} values ≤ 0 are drawn in the color of 1, the smallest "
                                                   "positive value (log color scale of data)")
    comp = window.controller.component("data")
    tf = window.controller.transfer_function("data")
    drawn = drawn_tf(comp, tf, window.controller.dataset_of("data"))
    pixels = widget_pixels(canvas).astype(int)
    row = int(canvas._plot_rect().bottom() + MARGIN + COLOR_BAR_HEIGHT / 2)
    values = np.array([2.0, 10.0, 50.0, 200.0])
    xs = np.rint(canvas.x_of(values)).astype(int)
    assert np.all(np.diff(xs) > 20)                      # a log axis: 2, 10, 50 and 200 spread across the width
    at_pixels = np.array([canvas.from_screen(QPointF(x + 0.5, row))[0] for x in xs])   # the values there
    rgb, _ = drawn.evaluate(at_pixels)
    expected = np.rint(np.clip(rgb, 0, 1) * 255).astype(int)
    shown = pixels[row, xs]
    assert np.abs(shown - expected).max() <= 2, (shown, expected)      # Qt's gradient: 8-bit steps
    linear, _ = tf.evaluate(values)                      # what a linear axis would show there: other colors
    assert np.abs(np.rint(np.clip(linear, 0, 1) * 255).astype(int) - shown).max() > 20

    _tick_log_scale(qtbot, window)                       # off again
    qtbot.waitUntil(lambda: canvas.log_floor is None, timeout=20000)
    lo, hi = canvas._view_range()
    assert canvas.x_of(lo + 0.5 * (hi - lo)) == pytest.approx(canvas._plot_rect().center().x())
