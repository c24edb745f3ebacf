"""The probe on every kind of volume in the real window (issue #28's missing tools): the mouse rests over the
viewport, the status bar shows the value under it, a click pins it. The value is checked exactly against the data:
the Blunt Fin's (drawn by projected tetrahedra) interpolated in its tetrahedron by hand and by VTK's probe, the
storm's at its voxel in the time step shown, the compressed volume's at its voxel in the decoded volume."""
from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from conftest import blob_vvz, data_file
from flows import click, hover, wait_loaded, wait_settled


def _open(qtbot, make_window, path):
    window = make_window()
    window.open_path(path)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    assert window.error_dialog is None, window.error_dialog.text()
    return window


def _probe_centre(qtbot, window, over=None):
    """Hover over the viewport's centre (or over the world point ``over``) until the probe answers; returns (the
    result, the pixel in VTK's display coordinates, the pixel in the widget's)."""
    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    if over is not None:
        renderer = window.plotter.renderer
        renderer.SetWorldPoint(*over, 1.0)
        renderer.WorldToDisplay()
        x, y, _ = renderer.GetDisplayPoint()
        ratio = canvas.devicePixelRatioF()
        centre = QPoint(round(x / ratio), round((window.plotter.ren_win.GetSize()[1] - 1 - y) / ratio))
    comp_id = window.controller.session.components[0].id
    hover(qtbot, canvas, centre)
    qtbot.waitUntil(lambda: window.probe.label.text().startswith(f"Probe: {comp_id}:"), timeout=10000)
    ratio = canvas.devicePixelRatioF()
    height = window.plotter.ren_win.GetSize()[1]
    return window.probe.last, np.array([centre.x() * ratio, height - 1 - centre.y() * ratio]), centre


def _projects_to(window, position, pixel, tolerance: float) -> None:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*position, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    assert np.hypot(x - pixel[0], y - pixel[1]) < tolerance, ((x, y), pixel)


def _pin_and_clear(qtbot, window, centre) -> None:
    text = window.probe.label.text()[len("Probe: "):]
    click(qtbot, window.plotter.interactor, centre)
    assert window.probe.pinned.count() == 1 and window.probe.pinned.item(0).text() == text
    assert window.probe.dock.isVisible()
    qtbot.mouseClick(window.probe.clear_button, Qt.MouseButton.LeftButton)
    assert window.probe.pinned.count() == 0


def test_probe_on_the_blunt_fin_interpolates_in_the_tetrahedron_under_the_cursor(qtbot, make_window) -> None:
    """Blunt Fin (curvilinear, drawn by volviz's PT): the hit lies on the cursor's ray, inside the tetrahedron named
    (a cell of the mesh drawn), and its value is the linear interpolation there, by hand and by VTK's probe."""
    import pyvista as pv

    from volviz.unstructured.probe import barycentric

    window = _open(qtbot, make_window, data_file("bluntfin/bluntfinxyz.bin"))
    hit, pixel, centre = _probe_centre(qtbot, window)
    view = window.controller.views[hit.component].prop
    assert view.kind == "pt"
    mesh = view.mesh
    assert hit.cell is not None and hit.voxel is None
    lam = barycentric(mesh.points, mesh.tets[hit.cell], np.array(hit.position))
    assert lam.min() > -1e-9, lam
    assert hit.value == pytest.approx(float(lam @ mesh.scalars[mesh.tets[hit.cell]]), rel=1e-12)
    sampled = pv.PolyData(np.array([hit.position])).sample(mesh.to_pyvista())
    assert hit.value == pytest.approx(float(sampled.point_data[mesh.name][0]), rel=1e-9)
    assert hit.point in mesh.tets[hit.cell]
    _projects_to(window, hit.position, pixel, 0.5)
    assert f"cell {hit.cell}" in window.probe.label.text()
    _pin_and_clear(qtbot, window, centre)


def test_probe_on_the_storm_reads_the_time_step_shown(qtbot, make_window) -> None:
    """Storm time series, three steps on with the timeline's button, the mouse over the densest voxel of the step
    shown: the value is the voxel's in the frame at the display time."""
    from volviz.model.timeseries import frame_at

    window = _open(qtbot, make_window, data_file("storm/Storm.pvm-t01"))
    first = window.controller.time
    for _ in range(3):
        qtbot.mouseClick(window.timeline.forward_button, Qt.MouseButton.LeftButton)
    wait_settled(qtbot, window)
    controller = window.controller
    series = next(iter(controller.time_series().values()))
    assert controller.time == pytest.approx(first + 3 * (series.times[1] - series.times[0]))
    shown = frame_at(series, controller.time, controller.interpolate_time)
    densest = np.unravel_index(np.argmax(shown.data), shown.data.shape)   # the storm is sparse: aim at its core
    hit, pixel, centre = _probe_centre(qtbot, window, np.asarray(shown.origin) + np.asarray(densest) *
                                       np.asarray(shown.spacing))
    assert hit.value == float(shown.data[hit.voxel])
    assert series.frame(0).data[hit.voxel] != hit.value      # the first step (constant) would read otherwise
    spacing = np.asarray(shown.spacing)
    _projects_to(window, np.asarray(hit.position), pixel, float(np.max(spacing)) * 4)
    _pin_and_clear(qtbot, window, centre)


def test_probe_on_a_compressed_lod_volume_reads_the_full_resolution_voxel(qtbot, make_window, tmp_path) -> None:
    """A .vvz of a 64^3 blob drawn at a level of detail: the value is the voxel's in the decoded volume."""
    from volviz.regular.codec import decompress

    path = blob_vvz(tmp_path / "blob.vvz", 64)
    window = _open(qtbot, make_window, path)
    hit, pixel, centre = _probe_centre(qtbot, window)
    assert hit.voxel is not None
    assert hit.value == float(decompress(path).data[hit.voxel])
    _projects_to(window, np.asarray(hit.position), pixel, 12.0)
    _pin_and_clear(qtbot, window, centre)


def test_probe_on_a_mesh_time_series_interpolates_in_the_step_shown(qtbot, make_window) -> None:
    """The dolfinx function (tetrahedra over 5 steps, drawn by VTK's volume mapper), two steps on: the value at the
    hit is VTK's probe of the mesh of the step shown there, on the cursor's ray."""
    import pyvista as pv

    from volviz.model.timeseries import frame_at

    window = _open(qtbot, make_window, data_file("ecosystem/dolfinx-function/no_checkpoint.xdmf"))
    for _ in range(2):
        qtbot.mouseClick(window.timeline.forward_button, Qt.MouseButton.LeftButton)
    wait_settled(qtbot, window)
    controller = window.controller
    series = next(iter(controller.time_series().values()))
    shown = frame_at(series, controller.time, controller.interpolate_time)
    assert controller.time > series.times[0]
    hit, pixel, centre = _probe_centre(qtbot, window)
    assert hit.cell is not None
    grid = shown.to_pyvista()
    sampled = pv.PolyData(np.array([hit.position])).sample(grid)
    assert hit.value == pytest.approx(float(sampled.point_data[grid.active_scalars_name][0]), rel=1e-6, abs=1e-9)
    first = pv.PolyData(np.array([hit.position])).sample(series.frame(0).to_pyvista())
    assert abs(float(first.point_data[grid.active_scalars_name][0]) - hit.value) > 1e-3   # not the first step's
    _projects_to(window, hit.position, pixel, 0.5)
    _pin_and_clear(qtbot, window, centre)
