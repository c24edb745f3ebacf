"""No multisampling in a plotter drawn by a software rasteriser, in the app's window and in ``volviz render`` alike
(``volviz.render.image_overlay.single_sample_on_software``), and the overlays' single-sample hold restores that."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from volviz.io import read
from volviz.render.backend import plotter_gl_info
from volviz.render.export import close_scene, offscreen_scene, open_target
from volviz.render.image_overlay import hold_single_sample, release_single_sample, single_sample_on_software
from volviz.render.offscreen import offscreen_plotter


def _plotter() -> pv.Plotter:
    plotter = offscreen_plotter((96, 64))
    plotter.ren_win.SetMultiSamples(4)
    plotter.add_mesh(pv.Sphere(), color="white")
    plotter.render()
    return plotter


def test_a_software_rasteriser_draws_single_sampled() -> None:
    plotter = _plotter()
    try:
        assert plotter_gl_info(plotter).software            # llvmpipe here
        overlay = object()
        hold_single_sample(plotter, overlay)                 # e.g. a PT overlay already in the plotter
        single_sample_on_software(plotter)
        assert plotter.ren_win.GetMultiSamples() == 0
        release_single_sample(plotter, overlay)              # the last overlay leaves: nothing to restore
        assert plotter.ren_win.GetMultiSamples() == 0
    finally:
        plotter.close()


def test_the_scene_controller_applies_the_rule(tmp_path) -> None:
    """``volviz render``'s plotter, as the app's window (tests/test_flow_*.py compare the two pictures)."""
    grid = pv.ImageData(dimensions=(8, 8, 8))
    grid.point_data["v"] = np.arange(grid.n_points, dtype=np.float64)
    grid.save(tmp_path / "ramp.vti")
    session, _ = open_target(tmp_path / "ramp.vti")
    volume = read(tmp_path / "ramp.vti")
    plotter, controller = offscreen_scene(session, {session.datasets[0].id: volume}, (96, 64))
    try:
        plotter.ren_win.SetMultiSamples(4)
        controller.build()
        assert plotter.ren_win.GetMultiSamples() == 0
    finally:
        close_scene(plotter, controller)
