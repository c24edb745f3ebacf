"""Slices through a volume from the Slices dock, in the real window (issue #28, "the missing tools")."""
from __future__ import annotations

import json

import numpy as np
from PySide6.QtCore import Qt

from conftest import data_file
from flows import (changed_share, compare_with_render, open_and_show_dock, screen, wait_loaded, wait_settled,
                   widget_pixels)

K = 41   # the z index the slider is moved to: 4 page steps of 10 and one step


def _expected_z_slice(volume, tf, k: int) -> np.ndarray:
    """The colours of slice z = k, computed here from the TF's control points: x across, y up (row 0 at the top),
    each sample clamped into the TF's range, the colour interpolated per channel, 8-bit rounded."""
    values = np.clip(volume.data[:, :, k].astype(np.float64), tf.scalars[0], tf.scalars[-1]).T[::-1]
    rgb = np.stack([np.interp(values, tf.scalars, tf.colors[:, c]) for c in range(3)], axis=-1)
    return np.rint(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)


def _shown_pixels(view) -> np.ndarray:
    """The 2D view's pixels (what it paints), one per sample: the centre of each zoomed cell."""
    z = view.zoom
    pixels = widget_pixels(view)[z // 2::z, z // 2::z]
    return pixels[:view.image.height(), :view.image.width()]


def test_a_z_slice_moved_by_its_slider_shows_the_tf_colours_of_its_samples(qtbot, make_window, tmp_path) -> None:
    """neghip: check Z in the Slices dock, move its slider to K with the keyboard; the 2D view's pixels are the TF
    colours of the volume's samples at z = K exactly, the 3D view shows the plane (it changed the picture), the
    session saves a slices component at z = K, and the screen matches ``volviz render`` of the saved session."""
    window = make_window()
    without = open_and_show_dock(qtbot, window, data_file("volumes/neghip.slc"), window.slices_dock)
    dock = window.slice_tool.dock
    qtbot.mouseClick(dock.checks["z"], Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: any(c.type == "slices" for c in window.controller.session.components), timeout=30000)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    slider = dock.sliders["z"]
    slider.setFocus()
    for _ in range(4):
        qtbot.keyClick(slider, Qt.Key.Key_PageUp)
    qtbot.keyClick(slider, Qt.Key.Key_Right)
    comp = next(c for c in window.controller.session.components if c.type == "slices")
    assert comp.settings == {"z": K}
    wait_settled(qtbot, window)

    volume = window.controller.dataset_of("data")
    tf = window.controller.transfer_function("data")
    assert comp.transfer_function == window.controller.component("data").transfer_function
    expected = _expected_z_slice(volume, tf, K)
    shown = _shown_pixels(dock.views["z"])
    assert shown.shape == (volume.dimensions[1], volume.dimensions[0], 3)
    assert len(np.unique(expected.reshape(-1, 3), axis=0)) > 10         # a slice with structure, not one colour
    assert np.array_equal(shown, expected), int(np.abs(shown.astype(int) - expected).max())
    assert dock.views["x"].image is None and dock.views["y"].image is None

    with_slice = screen(window)
    assert changed_share(with_slice, without) > 0.05, changed_share(with_slice, without)
    err = compare_with_render(window, tmp_path)
    print("screen vs volviz render:", err)
    saved = json.loads((tmp_path / "flow.json").read_text())
    assert [c["settings"] for c in saved["components"] if c["type"] == "slices"] == [{"z": K}]
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err

    window.action_undo.trigger()                 # the moves are one undo step: back to z = 0
    assert comp.settings == {"z": 0} and dock.spins["z"].value() == 0


def test_a_z_slice_dragged_in_the_3d_view_moves_its_slider_and_2d_view(qtbot, make_window) -> None:
    """neghip, Z checked (the plane at z = 0): a real press on the plane in the 3D view, moves and release up to
    where the plane z = K projects; the dock's slider and spin box read K, the 2D view's pixels are the TF colours
    of the samples at z = K exactly, the camera did not orbit, and one undo puts the plane back at 0."""
    from PySide6.QtCore import QPoint

    from flows import drag

    window = make_window()
    open_and_show_dock(qtbot, window, data_file("volumes/neghip.slc"), window.slices_dock)
    dock = window.slice_tool.dock
    qtbot.mouseClick(dock.checks["z"], Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: any(c.type == "slices" for c in window.controller.session.components), timeout=30000)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    volume = window.controller.dataset_of("data")
    canvas = window.plotter.interactor
    renderer = window.plotter.renderer
    ratio = canvas.devicePixelRatioF()
    height = window.plotter.ren_win.GetSize()[1]

    def on_screen(i: float, j: float, k: float) -> QPoint:
        renderer.SetWorldPoint(*(np.asarray(volume.origin) + np.array([i, j, k]) * np.asarray(volume.spacing)), 1.0)
        renderer.WorldToDisplay()
        x, y, _ = renderer.GetDisplayPoint()
        return QPoint(round(x / ratio), round((height - 1 - y) / ratio))

    middle = (volume.dimensions[0] - 1) / 2, (volume.dimensions[1] - 1) / 2
    camera = window.controller.camera()
    drag(qtbot, canvas, on_screen(*middle, 0), on_screen(*middle, K), steps=12)
    assert dock.sliders["z"].value() == K and dock.spins["z"].value() == K
    comp = next(c for c in window.controller.session.components if c.type == "slices")
    assert comp.settings == {"z": K}
    assert window.controller.views[comp.id].indices == {"z": K}     # the 3D plane moved
    after = window.controller.camera()
    assert np.allclose(after.position, camera.position) and np.allclose(after.focal_point, camera.focal_point)
    wait_settled(qtbot, window)
    expected = _expected_z_slice(volume, window.controller.transfer_function("data"), K)
    assert np.array_equal(_shown_pixels(dock.views["z"]), expected)
    window.action_undo.trigger()
    assert comp.settings == {"z": 0} and dock.sliders["z"].value() == 0
