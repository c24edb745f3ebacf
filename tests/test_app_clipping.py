"""Clipping planes, the isosurface transparency modes and the iso-spectrum shader in the app's real Qt viewport
(pytest-qt under Xvfb, real rendering)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from volviz.iso.composite import render
from volviz.model.camera import Camera

from volviz_app.window import MainWindow

STYLES = [{"value": 0.3, "color": [1.0, 0.3, 0.2], "opacity": 0.5},
          {"value": 0.8, "color": [0.2, 0.4, 1.0], "opacity": 0.4}]


def ball_session(tmp_path: Path, render: dict | None = None) -> Path:
    """A session of two isosurfaces (``STYLES``) of x² + y² + z² on a 24³ grid, written into ``tmp_path``."""
    g = np.linspace(-1, 1, 24)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    grid = pv.ImageData(dimensions=(24, 24, 24))
    grid.point_data["s"] = (x * x + y * y + z * z).ravel(order="F")
    grid.save(tmp_path / "ball.vti")
    doc = {"format": "volviz-session", "version": 1, "datasets": [{"id": "b", "path": "ball.vti"}],
           "components": [{"id": "iso", "type": "isosurface", "dataset": "b", "settings": {"styles": STYLES}}]}
    if render is not None:
        doc.update(render)
    path = tmp_path / "ball.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.fixture
def session_file(tmp_path: Path) -> Path:
    return ball_session(tmp_path, {
        "camera": {"position": [11.5, -45.0, 11.5], "focal_point": [11.5, 11.5, 11.5], "view_up": [0, 0, 1]},
        # the viewport is compared with CPU renders of the surfaces: no decorations
        # the note's modes by the CPU overlay (auto takes the GPU's, tests/test_app_iso_backend.py)
        "render": {"options": {"scalar_bar": False, "axes": False, "outline": False, "backend": "cpu"}}})


def open_session(qtbot, window: MainWindow, path: Path) -> None:
    window.open_path(path)
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible() and window.controller is not None, timeout=60000)
    window.plotter.ren_win.SetMultiSamples(0)


def viewport(window: MainWindow) -> np.ndarray:
    """The viewport once the isosurfaces show the current clipping (they are re-cut in the background)."""
    import time

    from PySide6.QtWidgets import QApplication

    deadline = time.monotonic() + 30.0
    while not window.clipping_shown() and time.monotonic() < deadline:
        QApplication.processEvents()
        time.sleep(0.005)
    assert window.clipping_shown(), "the isosurfaces were not re-cut for the new clipping"
    window.plotter.render()
    return np.asarray(window.plotter.screenshot(None, return_img=True)).astype(np.float64)


def pixel(window: MainWindow, point: tuple[float, float, float]) -> tuple[int, int]:
    """(row, col) of a world point in the viewport image."""
    w, h = window.plotter.ren_win.GetSize()
    px, py, _ = Camera.from_pyvista(window.plotter.camera).project(np.array(point), (w, h))
    return int(round(py)), int(round(px))


def test_clip_plane_cuts_the_view_undo_and_survives_save_and_reopen(qtbot, make_window, session_file, tmp_path):
    window = make_window()
    open_session(qtbot, window, session_file)
    before = viewport(window)
    left, right = pixel(window, (8.0, 11.5, 11.5)), pixel(window, (15.0, 11.5, 11.5))
    background = before[5, 5]
    assert np.abs(before[left] - background).max() > 20 and np.abs(before[right] - background).max() > 20

    dock = window.clipping
    shown = window.controller.props["iso"].volviz_shown
    dock.add_button.click()                              # a plane through the centre, normal +x: keeps x >= 11.5
    assert len(window.session.clip.planes) == 1 and window.dirty
    assert window.controller.props["iso"].volviz_shown is shown and not window.clipping_shown(), \
        "the isosurfaces were cut on the GUI thread"
    cut = viewport(window)
    assert np.abs(cut[left] - background).max() <= 3     # the left half is gone
    assert np.abs(cut[right] - before[right]).max() <= 3  # the right half is as it was
    dock.offset.setValue(13.0)                           # move the plane with the spin box
    assert window.session.clip.planes[0].point == pytest.approx([13.0, 0.0, 0.0])
    window.action_undo.trigger()                         # Edit > Undo acts on the clipping edits
    assert window.session.clip.planes[0].point == pytest.approx([11.5, 0.0, 0.0])
    assert np.abs(viewport(window) - cut).max() <= 3
    dock.undo_button.click()                             # undo the plane itself
    assert window.session.clip.planes == () and np.abs(viewport(window) - before).max() <= 3
    dock.redo_button.click()
    assert len(window.session.clip.planes) == 1

    saved = tmp_path / "clipped.json"
    assert window.save_session(saved)
    assert json.loads(saved.read_text())["clip"]["planes"][0]["normal"] == [1.0, 0.0, 0.0]
    other = make_window()
    open_session(qtbot, other, saved)
    assert other.session.clip == window.session.clip
    assert other.clipping.plane_list.count() == 1 and other.clipping.offset.value() == pytest.approx(11.5)
    reopened = viewport(other)
    assert np.abs(reopened[left] - background).max() <= 3
    assert np.abs(reopened[right] - cut[right]).max() <= 3

    # drag the plane in the viewport: the VTK plane widget's release edits the plane through the dock (undoable)
    other.clipping.show_widget.setChecked(True)
    widget = other.clip_widget.widget
    assert widget is not None and widget.GetNormal() == pytest.approx((1.0, 0.0, 0.0))
    widget.SetNormal(0.0, -1.0, 0.0)
    widget.SetOrigin(11.5, 11.5, 11.5)
    widget.InvokeEvent("EndInteractionEvent")
    assert other.session.clip.planes[0].normal == pytest.approx([0.0, -1.0, 0.0])
    assert other.session.clip.planes[0].point == pytest.approx([0.0, 11.5, 0.0])
    dragged = viewport(other)
    assert np.abs(dragged[left] - reopened[left]).max() > 20      # the plane now faces the camera: both
    assert np.abs(dragged[right] - reopened[right]).max() > 3     # halves show the cut (back) half
    other.clipping.undo_button.click()
    assert other.session.clip.planes[0].normal == pytest.approx([1.0, 0.0, 0.0])
    assert widget.GetNormal() == pytest.approx((1.0, 0.0, 0.0))   # the widget follows the dock
    other.clipping.box_enabled.setChecked(True)           # box crop: default box = the scene bounds; drag it
    box_widget = other.clip_widget.box_widget
    assert box_widget is not None and other.session.clip.box is not None
    top = pixel(other, (15.0, 11.5, 17.0))
    unboxed = viewport(other)
    assert np.abs(unboxed[top] - background).max() > 20
    box_widget.PlaceWidget([-5.0, 30.0, -5.0, 30.0, -5.0, 14.0])
    box_widget.InvokeEvent("EndInteractionEvent")
    box = other.session.clip.box
    assert box is not None and box.lo == pytest.approx((-5.0,) * 3) and box.hi == pytest.approx((30.0, 30.0, 14.0))
    boxed = viewport(other)
    assert np.abs(boxed[top] - background).max() <= 3                 # above z = 14: cropped
    low = pixel(other, (17.0, 11.5, 8.0))                             # (clear of the widgets' handles)
    assert np.abs(boxed[low] - unboxed[low]).max() <= 3 and np.abs(boxed[low] - background).max() > 20
    other.clipping.undo_button.click()
    assert np.abs(viewport(other) - unboxed).max() <= 3
    other.clipping.show_widget.setChecked(False)
    assert other.clip_widget.widget is None and other.clip_widget.box_widget is None


def test_transparency_mode_from_render_settings_and_spectrum_shader_on_screen(qtbot, make_window, session_file,
                                                                              tmp_path):
    window = make_window()
    for dock in (window.tf_dock, window.stats_dock, window.clip_dock):
        dock.hide()                              # room for the whole scene in the viewport
    open_session(qtbot, window, session_file)
    vtk_image = viewport(window)
    # the iso-spectrum shader compiles in the Qt viewport (it needs the lights that Plotter.clear removed): the
    # viewport equals the offscreen export, which always had it
    export = tmp_path / "export.png"
    w, h = window.plotter.ren_win.GetSize()
    window.export_screenshot(export, (w, h))
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=60000)  # rendered in the background
    assert window.export_result
    import imageio.v3 as iio
    offscreen = iio.imread(export)[..., :3].astype(np.float64)
    assert offscreen.shape == vtk_image.shape
    assert np.abs(offscreen - vtk_image).mean() < 1.0
    flat = [c for c in window.session.components if c.id == "iso"][0]
    assert window.apply_component_settings("iso", {**flat.settings, "shading": "flat"})
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible(), timeout=60000)  # rebuilt in the background
    window.plotter.ren_win.SetMultiSamples(0)
    assert np.abs(viewport(window) - vtk_image).mean() > 0.5  # constant opacity looks different

    assert window.apply_component_settings("iso", {"styles": STYLES})
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible(), timeout=60000)  # rebuilt in the background
    window.plotter.ren_win.SetMultiSamples(0)
    controller = window.controller
    window.render_settings.iso_mode.setCurrentText("3pass")
    assert window.controller is controller                # a mode switch does not rebuild the scene
    overlay = window.controller.iso_overlay
    assert overlay is not None and window.session.render.options["iso_mode"] == "3pass"
    qtbot.waitUntil(lambda: overlay.stats.get("method") == "iso 3pass" and overlay.stats.get("size") == (w, h),
                    timeout=30000)
    three = viewport(window)
    assert np.abs(three - vtk_image).mean() > 1.0
    cpu, _ = render(overlay.meshes, overlay.camera, (w, h), "3pass")
    bg = np.asarray(window.session.render.background) * 255.0
    expected = (cpu[..., :3] * 255.0 + (1.0 - cpu[..., 3:4]) * bg)
    err = np.abs(three - expected)[1:-1, 1:-1]  # (the overlay image's outermost pixels are not compared)
    assert err.max() <= 3.0 and err.mean() < 0.6
    window.resize(1000, 700)                           # a resized viewport re-renders the overlay at its new size
    qtbot.waitUntil(lambda: overlay.stats.get("size") == tuple(window.plotter.ren_win.GetSize()) != (w, h),
                    timeout=30000)
    window.render_settings.iso_mode.setCurrentText("vtk")
    assert window.controller.iso_overlay is None
    window.resize(1400, 900)
    qtbot.waitUntil(lambda: tuple(window.plotter.ren_win.GetSize()) == (w, h), timeout=10000)
    assert np.abs(viewport(window) - vtk_image).max() <= 3


def test_pt_volume_is_cut_in_the_background_and_re_rendered(qtbot, make_window):
    window = make_window()
    window.open_demo_volume()
    qtbot.waitUntil(lambda: not window.progress_bar.isVisible() and window.controller is not None, timeout=60000)
    volume = window.controller.pt_volume("demo")
    whole = volume.mesh
    lo, hi = whole.points.min(axis=0), whole.points.max(axis=0)
    qtbot.waitUntil(lambda: bool(volume.stats), timeout=30000)
    alpha = volume.image[..., 3].sum()
    window.clipping.set_box(lo, (lo + hi) / 2)
    qtbot.waitUntil(lambda: volume.mesh is not whole and volume.image[..., 3].sum() < 0.8 * alpha, timeout=60000)
    assert volume.mesh.points.max(axis=0) == pytest.approx((lo + hi) / 2)
    window.action_undo.trigger()
    qtbot.waitUntil(lambda: volume.image[..., 3].sum() == pytest.approx(alpha, rel=1e-6), timeout=60000)
    assert volume.mesh.n_cells == whole.n_cells


def test_isosurface_opacity_is_remade_in_the_background(qtbot, make_window, session_file):
    window = make_window()
    open_session(qtbot, window, session_file)
    before = viewport(window)
    shown = window.controller.props["iso"].volviz_shown
    window.scene_tree.opacity.setValue(30)  # the scene tree's opacity slider for the selected component ("iso")
    assert window.controller.component("iso").opacity == pytest.approx(0.3)
    assert window.controller.props["iso"].volviz_shown is shown, "the isosurfaces were re-made on the GUI thread"
    qtbot.waitUntil(lambda: window.controller.props["iso"].volviz_shown is not shown, timeout=30000)
    new = window.controller.props["iso"].volviz_shown
    assert [m.style.opacity for m in new] == pytest.approx([0.3 * s["opacity"] for s in STYLES])
    assert np.abs(viewport(window) - before).mean() > 0.5  # fainter surfaces
