"""Showing a component that was hidden at load (issue #5, "Background work"): its preparation (here generation,
tetrahedral topology and the first PT image of a 320,000-tetrahedron mesh) runs on a worker, only adding its prop
runs on the GUI thread. Under Xvfb with real widgets and real rendering."""
from __future__ import annotations

import json
from pathlib import Path

from PySide6.QtCore import Qt

from loop_latency import LoopGaps
from test_app_workflows import wait_loaded  # a helper shared with it (the make_window fixture is in conftest.py)


def test_showing_a_hidden_component_prepares_it_in_the_background(qtbot, make_window, tmp_path: Path) -> None:
    session = tmp_path / "hidden.json"
    session.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "components": [{"id": "small", "type": "demo", "settings": {"cells_per_edge": 6}},
                       {"id": "big", "type": "demo", "visible": False, "settings": {"cells_per_edge": 40}}],
        "camera": {"position": [3.2, -2.4, 2.0], "focal_point": [0.5, 0.5, 0.5], "view_up": [0, 0, 1]}}))
    window = make_window()
    window.resize(1000, 600)  # a small viewport: renders (on this thread) are not what this test is about
    qtbot.wait(300)  # the viewport's resize handling is over
    window.open_path(session)
    wait_loaded(qtbot, window)
    controller = window.controller
    assert "big" not in controller.props
    qtbot.wait(300)
    gaps = LoopGaps()
    window.scene_tree.item("big").setCheckState(0, Qt.CheckState.Checked)  # what a click on its box does
    assert "big" not in controller.props, "the hidden component was built on the GUI thread"
    qtbot.waitUntil(lambda: window.components_shown == 1, timeout=120000)
    volume = controller.pt_volume("big")
    assert volume is not None and volume.mesh.tets.shape[0] == 40 ** 3 * 5
    qtbot.waitUntil(lambda: volume.image is not None, timeout=120000)  # its first image, also in the background
    gaps.stop()
    assert volume.image[..., 3].max() > 0
    print(gaps.summary())
    gaps.assert_responsive("while showing it", 20)
    window.scene_tree.item("big").setCheckState(0, Qt.CheckState.Unchecked)  # hiding needs no rebuild
    assert not volume.visible and window.components_shown == 1


def test_natural_scene_adds_its_actors_without_rendering(qtbot, make_window) -> None:
    """The natural scene's sky, terrain and overlay are added with ``render=False`` (PyVista otherwise renders the
    whole scene after each added actor, 50-600 ms of a blocked GUI thread on llvmpipe): installing a rebuilt scene
    and finishing its first view draw nothing; the caller draws once."""
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    qtbot.waitUntil(lambda: not window._view_jobs["nature"].running, timeout=60000)
    controller = window.controller
    scene = controller.prepare_nature()
    renders = []
    tag = window.plotter.ren_win.AddObserver("StartEvent", lambda *_: renders.append(1))
    try:
        view = controller.install_nature(scene, views=False)  # a new NatureView: sky dome added
        request = view.begin()
        controller.finish_nature(view, request, view.compute(request))  # terrain and overlay added
    finally:
        window.plotter.ren_win.RemoveObserver(tag)
    assert view.sky_actor is not None and view.terrain_actor is not None and view._overlay_actor is not None
    assert renders == [], f"{len(renders)} renders while the natural scene was put in"
