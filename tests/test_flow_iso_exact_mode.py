"""The note's exact transparency mode chosen in the Isosurfaces dock, with a regular volume in the real window (issue
#28): a session of a translucent plane isosurface through a ball-shaped volume (``iso_volume_scene``) drawn in
3-pass mode; the user picks "Exact (sorted)" in the dock's Transparency list; the scene is drawn again in exact mode
(on the GPU, peeled together with the volume, ``volviz.render.gl_iso``), the saved session says so, and the screen is
the exact composite "volume in front, surface, volume behind" of the window's own renders and matches
``volviz render`` of the saved session."""
from __future__ import annotations

import json

from flows import assert_matches_render, open_and_show_dock, pick_combo_item, wait_loaded, wait_settled
from iso_volume_scene import session, write_datasets
from test_iso_modes_volume import errors
from volviz.session import save


def test_exact_mode_picked_in_the_dock_composites_the_surface_inside_the_volume(qtbot, make_window,
                                                                               tmp_path) -> None:
    """Bounds as the 3-pass flow (tests/test_iso_modes_volume_flow.py): over the surface's pixels RMSE < 1 level and
    at most 1e-4 of them off by more than 3 against the exact composite (the surface over the whole volume > 5); the
    screen against ``volviz render`` RMSE < 1.5, < 0.2 % of pixels off by more than 24 (tests/flows.py). The plane
    seen at the session's camera, one layer per ray, where VTK's peeling restarting the volume's samples at the layer
    does not show (module docstring of ``volviz.render.iso_volume_split``)."""
    path = tmp_path / "plane_in_ball.json"
    save(session("auto", "3pass", write_datasets(tmp_path)), path)
    window = make_window()
    open_and_show_dock(qtbot, window, path, window.iso_dock)
    dock = window.iso_tool.dock
    assert dock.mode.currentData() == "3pass"
    assert window.controller.iso_view.mode == "3pass" and window.controller.iso_view.backend == "cpu"

    pick_combo_item(qtbot, dock.mode, "exact")
    qtbot.waitUntil(lambda: window.controller is not None and window.controller.iso_view is not None
                    and window.controller.iso_view.mode == "exact", timeout=60000)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    view = window.controller.iso_view
    assert view.backend == "gpu" and view.peels_volumes           # peeled together with the volume
    assert window.controller.iso_overlay is None
    assert dock.mode.currentData() == "exact"

    e = errors(window.controller, window.plotter, "exact")
    print("exact mode against the exact composite:", e)
    assert e["share"] > 0.05                                      # the surface is in view
    assert e["rmse"] < 1.0 and e["over3"] <= 1e-4 * e["pixels"], e
    assert e["old_rmse"] > 5.0                                    # the surface over the whole volume: far off

    print("screen vs volviz render:", assert_matches_render(window, tmp_path, "exact", 1.5, 0.002))
    saved = json.loads((tmp_path / "exact.json").read_text())
    assert saved["render"]["options"]["iso_mode"] == "exact"
