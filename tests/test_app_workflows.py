"""What a user does in the app, under Xvfb with real widgets and real VTK rendering (issue: the desktop application)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt, QTimer
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication, QMessageBox

from conftest import data_file
from flows import wait_settled
from loop_latency import LoopGaps
from volviz_app.window import MainWindow


def wait_loaded(qtbot, window: MainWindow) -> None:
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible() and window.controller is not None, timeout=60000)


def viewport(window: MainWindow) -> np.ndarray:
    window.plotter.render()
    return np.asarray(window.plotter.screenshot(None, return_img=True)).astype(np.float64)


def test_open_data_through_the_menu_action(qtbot, make_window) -> None:
    window = make_window()
    path = data_file("volumes/neghip.slc")
    window.action_open_data.trigger()
    dialog = window.file_dialog
    assert dialog.isVisible() and dialog.nameFilters()[0].startswith("All supported")
    dialog.selectFile(str(path))
    dialog.accept()
    wait_loaded(qtbot, window)
    assert window.error_dialog is None
    assert "neghip.slc" in window.windowTitle()
    assert window.scene_tree.tree.topLevelItemCount() == 1
    assert window.recent_files()[0] == str(path.resolve())
    assert viewport(window).std() > 5.0


def _mouse(widget, kind: QEvent.Type, pos: QPoint, buttons: Qt.MouseButton) -> None:
    local = QPointF(pos)
    event = QMouseEvent(kind, local, widget.mapToGlobal(local), Qt.MouseButton.LeftButton, buttons,
                        Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(widget, event)


def _drag(qtbot, canvas, start: QPoint, end: QPoint) -> None:
    """A real press-move-release sequence delivered through Qt's event system."""
    held = Qt.MouseButton.LeftButton
    _mouse(canvas, QEvent.Type.MouseButtonPress, start, held)
    for k in range(1, 6):
        _mouse(canvas, QEvent.Type.MouseMove, start + (end - start) * (k / 5), held)
        qtbot.wait(20)
    _mouse(canvas, QEvent.Type.MouseButtonRelease, end, Qt.MouseButton.NoButton)


def test_drag_transfer_function_point_changes_image_and_undo_restores_it(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    before = viewport(window)
    tf_before = window.tf_editor.transfer_function
    canvas = window.tf_editor.canvas
    # a middle point of the automatic function's opacity ramp: dragged to the bottom it makes most of the volume's
    # visible part (the values above it) far more transparent
    index = len(tf_before) // 2
    p = canvas.to_screen(tf_before.scalars[index], tf_before.extinction[index])
    start = QPoint(int(p.x()), int(p.y()))
    _drag(qtbot, canvas, start, QPoint(start.x(), canvas._plot_rect().bottom() - 2))
    qtbot.wait(300)  # let the throttled preview render
    after = viewport(window)
    tf_after = window.tf_editor.transfer_function
    assert tf_after.extinction[index] < 0.1 * tf_before.extinction[index]
    changed = (np.abs(after - before).sum(axis=2) > 10).mean()
    assert changed > 0.01, f"image did not change ({changed:.2%} of the pixels changed)"
    assert window.dirty
    assert window.tf_editor.undo_stack.count() == 1

    window.tf_editor.undo_stack.undo()
    qtbot.wait(300)
    restored = viewport(window)
    assert window.tf_editor.transfer_function == tf_before
    assert np.abs(restored - before).max() <= 2.0
    window.tf_editor.undo_stack.redo()
    assert window.tf_editor.transfer_function == tf_after


def test_save_and_reopen_session_gives_the_same_image(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    window.plotter.camera.azimuth = 40.0
    window.plotter.camera.elevation = 20.0
    window.tf_editor.apply_preset(window.tf_editor._preset_names()[0])
    qtbot.wait(200)
    image = viewport(window)
    session_file = tmp_path / "neghip-session.json"
    assert window.save_session(session_file)
    assert not window.dirty

    other = make_window()
    other.open_path(session_file)
    wait_loaded(qtbot, other)
    assert other.session.transfer_functions == window.session.transfer_functions
    reopened = viewport(other)
    assert reopened.shape == image.shape
    assert np.abs(reopened - image).mean() < 0.5


def test_timeline_plays_the_storm_series(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(data_file("storm/Storm.pvm-t01"))
    wait_loaded(qtbot, window)
    assert window.timeline.steps == [float(i) for i in range(1, 22)]
    first = viewport(window)
    window.timeline.speed.setValue(20.0)
    window.timeline.set_playing(True)
    # (playback frames are short now: stopped just past t = 5 the image differs by only ~0.15-0.2 on average)
    qtbot.waitUntil(lambda: window.timeline.time > 7.0, timeout=10000)
    window.timeline.set_playing(False)
    assert window.controller.time == pytest.approx(window.timeline.time)
    # the blended volume of the display time is made in the background, then shown
    qtbot.waitUntil(lambda: window.volume_time_shown == (window.controller.time, True), timeout=10000)
    assert np.abs(viewport(window) - first).mean() > 0.2, "the volume did not change over time"
    window.timeline.set_time(1.5)  # between two steps: interpolated data
    a = window.controller.datasets["data"].frame(0).data.astype(np.float32)
    b = window.controller.datasets["data"].frame(1).data.astype(np.float32)
    from volviz.model.timeseries import frame_at

    assert np.allclose(frame_at(window.controller.datasets["data"], 1.5).data, 0.5 * (a + b))
    # a scene without a time series: the timeline is disabled and back at its start
    assert window.timeline.slider.value() > 0
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    assert window.timeline.steps == [] and not window.timeline.slider.isEnabled()
    assert window.timeline.slider.value() == 0 and window.timeline.time == 0.0
    assert window.timeline.label.text() == "no time series"


def test_fly_forward_with_keys_moves_the_camera(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    window.set_fly_mode(True)
    cam = window.plotter.camera
    start = np.array(cam.position)
    direction = np.array(cam.focal_point) - start
    direction /= np.linalg.norm(direction)
    for _ in range(5):
        qtbot.keyClick(window.plotter.interactor, Qt.Key.Key_W)
    moved = np.array(window.plotter.camera.position) - start
    assert np.linalg.norm(moved) > 0
    assert np.dot(moved, direction) == pytest.approx(np.linalg.norm(moved), rel=1e-6)  # straight ahead
    qtbot.keyClick(window.plotter.interactor, Qt.Key.Key_D)
    sideways = np.array(window.plotter.camera.position) - start - moved
    assert abs(np.dot(sideways, direction)) < 1e-9 * max(np.linalg.norm(sideways), 1)
    window.set_fly_mode(False)
    position = np.array(window.plotter.camera.position)
    qtbot.keyClick(window.plotter.interactor, Qt.Key.Key_Up)  # orbit mode: keys are VTK's again
    assert np.allclose(window.plotter.camera.position, position)


def test_bookmarks_and_recorded_path_are_saved_and_render_a_movie(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    window.add_bookmark("start")
    window.set_recording(True)
    for azimuth in (10, 20, 30):
        window.plotter.camera.azimuth = azimuth
        qtbot.wait(300)
    name = window.set_recording(False)
    assert name in window.session.camera_paths and len(window.session.camera_paths[name]) >= 3
    session_file = tmp_path / "paths.json"
    assert window.save_session(session_file)
    doc = json.loads(session_file.read_text())
    assert "start" in doc["bookmarks"] and name in doc["camera_paths"]
    frames = tmp_path / "frames"
    window.export_movie(frames, name, through_time=False, fps=4, size=(96, 64))
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)  # rendered in the background
    assert window.export_result is True
    pngs = sorted(frames.glob("frame_*.png"))
    assert len(pngs) >= 3
    assert iio.imread(pngs[0]).shape[:2] == (64, 96)
    assert np.abs(iio.imread(pngs[0]).astype(int) - iio.imread(pngs[-1]).astype(int)).mean() > 0.5


def test_export_screenshot_any_size(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    out = tmp_path / "shot.png"
    window.export_screenshot(out, size=(1000, 333))
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=60000)  # rendered in the background
    assert window.export_result
    image = iio.imread(out)
    assert image.shape[:2] == (333, 1000)
    assert image[..., :3].std() > 3.0


def test_cancel_a_long_job_and_ui_stays_responsive(qtbot, make_window) -> None:
    window = make_window()
    from volviz.optics import TransferFunction
    from volviz.optics.tables import build_table3d_job

    tf = TransferFunction([0.0, 0.5, 1.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 30.0, 2.0])
    outcomes = []
    window._set_busy(True)
    job = window.jobs.submit(build_table3d_job, tf, n_s=512, n_l=256, l_max=1.0, name="table",
                             on_done=outcomes.append)
    window.scene_loading.current_job = job
    gaps = LoopGaps()
    qtbot.waitUntil(lambda: window.progress_bar.value() > 0, timeout=30000)
    gaps.restart()  # from the first progress report on: the one-time Numba compilation (cached on disk) is over
    qtbot.wait(1500)
    qtbot.mouseClick(window.cancel_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: bool(outcomes), timeout=30000)
    gaps.stop()
    assert outcomes[0].cancelled and outcomes[0].result is None
    gaps.assert_responsive("while a long job ran", 50)


def test_autosave_and_recovery_after_a_crash(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    window.scene_tree.opacity.setValue(40)  # an unsaved change
    assert window.dirty
    assert window.autosave()  # what the 60 s timer runs
    assert window.recovery_file.exists()
    # "crash": the process owning the autosave ends without a clean close, so its recovery file stays (here the file
    # passes to a process that has ended; tests/test_app_recovery.py SIGKILLs a real app process)
    window.dirty = False
    window.autosave_timer.stop()
    ended = subprocess.Popen([sys.executable, "-c", "pass"])
    ended.wait()
    window.recovery_file.rename(window.recovery_file.with_name(f"recovery-{ended.pid}-0.json"))

    restarted = make_window()
    assert restarted.offer_recovery()
    qtbot.waitUntil(lambda: restarted.recovery_dialog is not None and restarted.recovery_dialog.isVisible())
    restarted.recovery_dialog.button(QMessageBox.StandardButton.Yes).click()
    wait_loaded(qtbot, restarted)
    assert restarted.session.components[0].opacity == pytest.approx(0.4)
    assert restarted.dirty


def test_unsaved_changes_prompt_can_cancel_closing(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    window.scene_tree.opacity.setValue(50)
    assert window.dirty

    def press_cancel() -> None:
        box = getattr(window, "unsaved_dialog", None)
        if box is not None and box.isVisible():
            box.button(QMessageBox.StandardButton.Cancel).click()
        else:
            QTimer.singleShot(50, press_cancel)

    QTimer.singleShot(50, press_cancel)
    window.close()
    assert window.isVisible()  # still open: the user cancelled


def test_fly_over_terrain_never_goes_below_the_ground(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    terrain = window.controller.nature.scene.terrain
    window.set_fly_mode(True)
    window.fly.navigator.speed *= 20
    for _ in range(3):
        qtbot.keyClick(window.plotter.interactor, Qt.Key.Key_Q)  # sink
    x, y, z = window.plotter.camera.position
    assert z >= terrain.height_at(x, y)
    assert z == pytest.approx(terrain.height_at(x, y) + window.fly.navigator.clearance)


def test_paraview_preset_export_import_round_trip_and_bad_file(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    editor = window.tf_editor
    editor.apply_preset("viridis")
    exported = tmp_path / "viridis.json"
    editor.export_paraview(str(exported))
    colors = editor.transfer_function.colors.copy()
    editor.apply_preset("grayscale")
    assert not np.allclose(editor.transfer_function.colors, colors)
    assert editor.import_paraview(str(exported))
    assert np.allclose(editor.transfer_function.colors, colors, atol=1e-6)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert not editor.import_paraview(str(bad))
    assert "bad.json" in editor.error_dialog.text()
    assert window.isVisible()


def test_dock_layout_is_restored_from_the_session(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    window.timeline_dock.hide()
    window.removeDockWidget(window.stats_dock)
    window.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, window.stats_dock)
    window.stats_dock.show()
    session_file = tmp_path / "layout.json"
    assert window.save_session(session_file)

    other = make_window()
    assert other.timeline_dock.isVisible()
    other.open_path(session_file)
    wait_loaded(qtbot, other)
    assert not other.timeline_dock.isVisible()
    assert other.dockWidgetArea(other.stats_dock) == Qt.DockWidgetArea.LeftDockWidgetArea


def test_unstructured_data_renders_with_volviz_pt_and_shows_the_frame_split(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("bluntfin/bluntfinxyz.bin"))
    wait_loaded(qtbot, window)
    assert window.controller.pt_stats(), "the Blunt Fin is not drawn by volviz's PT renderer"
    pt_image = viewport(window)
    for key in ("split", "frame"):
        assert "ms" in window.statistics.text(key)
    assert window.statistics.text("method") == "pt"
    qtbot.waitUntil(lambda: "vs exact" in window.statistics.text("error"), timeout=60000)
    rmse = float(window.statistics.text("error").split()[1].rstrip(","))
    assert 0.0 <= rmse <= 1.0  # the fast path's measured error for this very view is within the product's budget
    table = {k: window.render_settings.settings()["options"][k] for k in ("table", "table_resolution")}
    assert table != {"table": "separable-4", "table_resolution": 512}     # not the finest table already
    window.render_settings.method.setCurrentText("vtk")  # VTK's own projected-tetrahedra mapper instead
    # drawn as an image off the GUI thread too (``volviz.render.vtk_pt_image``), with its own statistics and error
    qtbot.waitUntil(lambda: [s.get("method") for s in window.controller.pt_stats().values()] == ["vtk"],
                    timeout=30000)
    wait_settled(qtbot, window)
    assert window.statistics.text("method") == "vtk"
    qtbot.waitUntil(lambda: "vs exact" in window.statistics.text("error"), timeout=60000)
    vtk_rmse = float(window.statistics.text("error").split()[1].rstrip(","))
    assert vtk_rmse > rmse
    wait_settled(qtbot, window)
    # over the budget, VTK's method gets a message and keeps the user's table (volviz's table draws nothing of it)
    assert {k: window.session.render.options[k] for k in table} == table
    assert window.status_label.text().startswith(f"Measured error {vtk_rmse:.2f} of VTK's projected tetrahedra")
    vtk_image = viewport(window)
    assert pt_image.std() > 3.0 and vtk_image.std() > 3.0  # neither is blank
    assert np.abs(vtk_image - pt_image).mean() > 0.2  # and they are different renderers


def test_compressed_volume_decodes_in_the_background_and_shows(qtbot, make_window, tmp_path: Path) -> None:
    from volviz.cli import main as cli

    compressed = tmp_path / "neghip.vvz"
    assert cli(["compress", str(data_file("volumes/neghip.slc")), "-o", str(compressed), "--lossless"]) == 0
    window = make_window()
    window.open_path(compressed)
    wait_loaded(qtbot, window)
    assert window.error_dialog is None
    from volviz.io import read

    original = read(data_file("volumes/neghip.slc"))
    assert np.array_equal(window.datasets["data"].data, original.data)  # lossless through the app's loader
    assert viewport(window).std() > 3.0


def test_pt_volume_transfer_function_edits_render_in_the_background(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    assert window.controller.pt_volume("demo") is not None
    qtbot.waitUntil(lambda: window.view_updates.get("pt:demo", 0) >= 1, timeout=30000)   # its first image is shown
    before = viewport(window)
    background = np.asarray(window.session.render.background) * 255.0
    assert (np.abs(before[..., :3] - background).max(axis=2) > 30).mean() > 0.05          # the volume is drawn
    tf = window.tf_editor.transfer_function
    window.tf_editor.edit(tf.scaled_extinction(0.05), "Thin out")  # as a finished drag would

    def changed() -> bool:          # the image for the new TF is made in the background and then shown
        after = viewport(window)
        h, w = min(before.shape[0], after.shape[0]), min(before.shape[1], after.shape[1])  # docks may shift a few px
        return bool(np.abs(after[:h, :w] - before[:h, :w]).mean() > 0.5)

    qtbot.waitUntil(changed, timeout=30000)
    assert window.controller.pt_volume("demo").tf == tf.scaled_extinction(0.05)


def test_pt_volume_follows_the_camera_with_background_rendering(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    volume = window.controller.pt_volume("demo")
    first = volume.image.copy()
    window.plotter.camera.azimuth = 35.0
    window.plotter.camera.elevation = 25.0
    window._camera_moved()  # what the end of a mouse interaction triggers
    assert volume.image is not None and np.array_equal(volume.image, first)  # not yet: it renders in the background
    qtbot.waitUntil(lambda: not np.array_equal(volume.image, first), timeout=30000)
    assert volume.camera.position == pytest.approx(tuple(window.plotter.camera.position))


def test_component_settings_edited_in_the_scene_tree(qtbot, make_window, tmp_path: Path) -> None:
    storm = data_file("storm/Storm.pvm-t01").parent
    session_file = tmp_path / "iso.json"
    session_file.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "storm", "path": str(storm / "Storm.pvm-t%02d")}],
        "components": [{"id": "iso", "type": "isosurface", "dataset": "storm",
                        "settings": {"styles": [{"value": 200, "color": [1, 0.8, 0.2], "opacity": 0.8}]}}],
        "camera": {"position": [80, -40, 60], "focal_point": [14, 14, 11], "view_up": [0, 0, 1]},
        "render": {"options": {"time": 12.5}}}))
    window = make_window()
    window.open_path(session_file)
    wait_loaded(qtbot, window)
    form = window.scene_tree.form
    value = form.editor("styles").table.cellWidget(0, 0)  # the first surface's iso-value in the styles table
    assert value.value() == 200
    before = viewport(window)
    value.lineEdit().selectAll()
    qtbot.keyClicks(value.lineEdit(), "40")  # a lower iso-value: a much larger surface
    qtbot.keyClick(value.lineEdit(), Qt.Key.Key_Return)
    wait_loaded(qtbot, window)  # the scene is rebuilt in the background, then swapped in
    assert window.session.components[0].settings["styles"][0]["value"] == 40 and window.dirty
    assert (np.abs(viewport(window) - before).sum(axis=2) > 30).mean() > 0.01
    # the spin box allows 0 (the bound of a "greater than" field), the model refuses it: a message names the field
    controller, form = window.controller, window.scene_tree.form
    density = form.editor("triangles_per_pixel2")
    assert density.minimum() == 0.0
    density.setValue(0.0)
    density.editingFinished.emit()
    assert "triangles_per_pixel2" in form.problem("triangles_per_pixel2")
    assert not window.progress_bar.isVisible() and window.controller is controller  # nothing rebuilt
    assert window.session.components[0].settings == form.settings
    assert window.session.components[0].settings["styles"][0]["value"] == 40
    assert "triangles_per_pixel2" not in window.session.components[0].settings


def test_error_budget_switches_to_the_most_accurate_table(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    window.render_settings.error_budget.setValue(0.0)  # any measured error is above it
    qtbot.waitUntil(lambda: window.session.render.options.get("table") == "separable-4", timeout=60000)
    assert window.session.render.options["table_resolution"] == 512
    assert window.render_settings.table_kind.currentText() == "separable-4"
    qtbot.waitUntil(lambda: "vs exact" in window.statistics.text("error"), timeout=60000)


def test_fit_to_data_range(qtbot, make_window) -> None:
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    editor = window.tf_editor
    editor.edit(editor.transfer_function.rescaled(50.0, 60.0), "narrow")
    editor.fit_to_data()
    assert editor.transfer_function.range == pytest.approx((0.0, 255.0))
    editor.undo_stack.undo()
    assert editor.transfer_function.range == pytest.approx((50.0, 60.0))
