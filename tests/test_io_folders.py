"""Opening a folder that no reader opens itself (``volviz.io.folders``): a simulation's output folder shows its one
collection file, else its largest numbered series of readable files, through ``volviz.io.read``, the app's
``data_session`` and File > Open Folder."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

import volviz.io as vio
from test_app_window import wait_loaded, window  # noqa: F401  (the fixture)
from volviz.io.errors import ReadError
from volviz.io.folders import folder_target
from volviz.model import TimeSeries
from volviz.scene.opening import data_session


def _outputs(folder, name="out_{:04d}.vtu", steps=4, n=4):
    folder.mkdir(exist_ok=True)
    mesh = pv.ImageData(dimensions=(n, n, n)).cast_to_unstructured_grid().triangulate()
    for i in range(steps):
        mesh.point_data["p"] = mesh.points[:, 0] + 100.0 * i
        mesh.save(folder / name.format(i))
    return folder


def test_a_folder_of_numbered_outputs_is_their_time_series(tmp_path):
    folder = _outputs(tmp_path / "run")
    _outputs(folder, name="probe_{}.vtu", steps=3)                   # a smaller series beside it
    (folder / "notes_1.txt").write_text("a")
    (folder / "notes_2.txt").write_text("b")
    (folder / "notes_3.txt").write_text("c")
    assert folder_target(folder) == str(folder / "out_%04d.vtu")
    series = vio.read(folder)
    assert isinstance(series, TimeSeries) and len(series) == 4
    np.testing.assert_array_equal(series.times, [0.0, 1.0, 2.0, 3.0])
    assert series.frame(3).point_data["p"].min() == 300.0
    session = data_session(folder)
    assert session.datasets[0].path == str((folder / "out_%04d.vtu").resolve())
    assert session.render.options["time"] == 0.0


def test_a_collection_file_goes_before_the_numbered_files_it_lists(tmp_path):
    folder = _outputs(tmp_path / "run")
    rows = "".join(f'<DataSet timestep="{0.5 * i}" file="out_{i:04d}.vtu"/>' for i in range(4))
    (folder / "run.pvd").write_text(f'<VTKFile type="Collection"><Collection>{rows}</Collection></VTKFile>')
    assert folder_target(folder) == str(folder / "run.pvd")
    np.testing.assert_array_equal(vio.read(folder).times, [0.0, 0.5, 1.0, 1.5])      # the collection's times


def test_a_folder_with_nothing_to_show_says_so(tmp_path):
    (tmp_path / "a_1.txt").write_text("x")
    (tmp_path / "readme.md").write_text("x")
    assert folder_target(tmp_path) is None
    with pytest.raises(ReadError, match="nor does it hold one collection file .* or a numbered series"):
        vio.read(tmp_path)


def test_open_folder_in_the_app_shows_the_series(qtbot, window, tmp_path):  # noqa: F811
    folder = _outputs(tmp_path / "run")
    window.open_path(folder)
    wait_loaded(qtbot, window)
    assert window.error_dialog is None
    assert window.session.datasets[0].path == str((folder / "out_%04d.vtu").resolve())
    assert window.timeline.steps == [0.0, 1.0, 2.0, 3.0] and window.timeline.slider.isEnabled()
