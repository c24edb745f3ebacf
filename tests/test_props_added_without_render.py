"""Adding a scene's props to a shown plotter draws nothing: the caller renders once when the scene is complete
(issue #28: pyvista's ``add_actor`` / ``add_mesh`` / ``reset_camera`` render by default, so installing a regular
volume drew a still frame, its ray cast 150-330 ms at the window's size on this machine, before the first render
drew it again)."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from volviz.model.datasets import Image2D, RegularVolume
from volviz.render.framing import frame_bounds
from volviz.render.vtk_scene import add_dataset, apply_camera


def _shown_plotter() -> pv.Plotter:
    plotter = pv.Plotter(off_screen=True, window_size=(96, 64))
    plotter.show(auto_close=False)      # from here pyvista renders on each add unless told not to
    return plotter


def _renders(plotter: pv.Plotter, make) -> int:
    count = [0]
    tag = plotter.ren_win.AddObserver("StartEvent", lambda *args: count.__setitem__(0, count[0] + 1))
    try:
        make()
    finally:
        plotter.ren_win.RemoveObserver(tag)
    return count[0]


def test_a_shown_plotter_renders_on_a_plain_add() -> None:
    """The premise: pyvista renders a shown plotter on ``add_mesh`` (so the counts below can fail)."""
    plotter = _shown_plotter()
    try:
        assert _renders(plotter, lambda: plotter.add_mesh(pv.Sphere())) == 1
    finally:
        plotter.close()


def test_volumes_surfaces_images_and_cameras_are_set_without_a_render() -> None:
    plotter = _shown_plotter()
    data = np.fromfunction(lambda i, j, k: i + 2 * j + 3 * k, (6, 7, 8))
    grey = Image2D(np.arange(30, dtype=np.float64).reshape(5, 6))
    colour = Image2D(np.arange(90, dtype=np.float64).reshape(5, 6, 3), maxval=89)
    try:
        assert _renders(plotter, lambda: add_dataset(plotter, RegularVolume(data), name="volume")) == 0
        assert _renders(plotter, lambda: add_dataset(plotter, grey, name="grey")) == 0
        assert _renders(plotter, lambda: add_dataset(plotter, colour, name="colour")) == 0
        assert _renders(plotter, lambda: apply_camera(plotter, None)) == 0
        assert _renders(plotter, lambda: frame_bounds(plotter, None)) == 0
        assert {"volume", "grey", "colour"} <= set(plotter.actors)
    finally:
        plotter.close()
