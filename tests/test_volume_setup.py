"""The CPU ray caster's per-volume set-up is made off the GUI thread before a volume is shown
(``volviz.render.volume_setup``, issue #28): the lit embryo's first render on the GUI thread computed its gradients
there (the 256^3 volume's first frame 620 ms here, 162 ms after the set-up), and the picture is the same."""
from __future__ import annotations

import json
import threading

import numpy as np
import pyvista as pv
import pytest
from PySide6.QtCore import Qt

from conftest import data_file
from flows import wait_loaded, wait_settled
from volviz.io import read
from volviz.render.volume_setup import VolumeSetup, cpu_ray_cast, shared_setup
from volviz.render.vtk_scene import default_transfer_function_for, make_volume, volume_input


@pytest.fixture(scope="module")
def neghip():
    dataset = read(data_file("volumes/neghip.slc"))
    return volume_input(dataset), default_transfer_function_for(dataset)


def _gradients_counted(volume) -> list[int]:
    """A list that grows by one each time ``volume``'s CPU ray caster computes its gradients."""
    seen: list[int] = []
    volume.GetMapper().AddObserver("VolumeMapperComputeGradientsStartEvent", lambda *args: seen.append(1))
    return seen


def _first_frame(volume) -> np.ndarray:
    plotter = pv.Plotter(off_screen=True, window_size=[96, 80])
    try:
        plotter.add_actor(volume, reset_camera=True, render=False)
        plotter.camera.azimuth = 30
        plotter.render_window.Render()
        return np.asarray(plotter.screenshot(None, return_img=True)).astype(int)
    finally:
        plotter.close()


def test_a_set_up_volume_is_drawn_without_its_set_up_and_the_same(neghip) -> None:
    data, tf = neghip
    setup = VolumeSetup()
    try:
        volume = make_volume(data, True, tf, 1.0, cpu=True, shade=True)
        plain = make_volume(data, True, tf, 1.0, cpu=True, shade=True)
        assert cpu_ray_cast(volume) and not cpu_ray_cast(make_volume(data, True, tf, 1.0, cpu=False))
        made, made_plain = _gradients_counted(volume), _gradients_counted(plain)
        ticket = setup.hold([volume])
        assert setup.run(ticket) == 1
        setup.release(ticket)
        assert made == [1]                                   # made by the set-up, on the window's thread
        assert setup.gl.threads and threading.get_ident() not in setup.gl.threads
        shown, reference = _first_frame(volume), _first_frame(plain)
        assert made == [1] and made_plain == [1]             # not made again by the first frame
        assert reference.std() > 5.0                         # (a picture of the volume)
        np.testing.assert_array_equal(shown, reference)
        assert setup.run(ticket) == 0                        # released: nothing left to set up
    finally:
        setup.close()


def test_the_app_shows_a_regular_volume_set_up_off_the_gui_thread(qtbot, make_window) -> None:
    """Opening neghip on this machine (CPU ray caster): its volume is set up by the loading's set-up job, on the
    process's set-up window's thread (made at the window's start-up: making it holds the GIL), before it is
    installed; the window then shows it (and ``volviz render``'s picture, as the regular flows check). Closing the
    last app window closes the set-up window: an X connection left open made the process's exit fail once the X
    server had gone (tests/test_native_viewport_in_process.py)."""
    window = make_window()
    setup = shared_setup()
    assert setup.gl.calls >= 1 and "window" in setup.gl.state        # primed before any scene
    calls = setup.gl.calls
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    assert window.scene_loading.volume_setup is setup and setup.gl.calls == calls + 1
    assert threading.get_ident() not in setup.gl.threads
    volume = window.controller.views["data"].prop
    assert cpu_ray_cast(volume) and window.plotter.renderer.HasViewProp(volume)
    assert not setup._held                                    # released once installed
    window.dirty = False
    window.close()                   # the last app window: the set-up window (and its X connection) closes with it
    assert setup.closed and setup.run(1) == 0


def test_a_volume_hidden_at_load_and_shown_later_is_set_up_off_the_gui_thread(qtbot, make_window, tmp_path) -> None:
    """A regular volume hidden at load and shown from the scene tree goes through the same set-up as a loaded one
    (``volume_setup_job``): its gradients (lit) were made by its first render on the GUI thread."""
    session = tmp_path / "hidden.json"
    session.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "neghip", "path": str(data_file("volumes/neghip.slc"))}],
        "components": [{"id": "box", "type": "demo", "settings": {"cells_per_edge": 3}},
                       {"id": "vol", "type": "volume", "dataset": "neghip", "visible": False,
                        "settings": {"shade": True}}]}))
    window = make_window()
    window.open_path(session)
    wait_loaded(qtbot, window)
    setup = shared_setup()
    calls = setup.gl.calls
    assert "vol" not in window.controller.views
    window.scene_tree.item("vol").setCheckState(0, Qt.CheckState.Checked)     # what a click on its box does
    qtbot.waitUntil(lambda: window.components_shown == 1, timeout=60000)
    assert setup.gl.calls == calls + 1 and not setup._held
    volume = window.controller.views["vol"].prop
    assert cpu_ray_cast(volume) and window.plotter.renderer.HasViewProp(volume)
    made = _gradients_counted(volume)
    wait_settled(qtbot, window)
    window.plotter.render()
    assert made == []                                           # made by the set-up, not by a render here
