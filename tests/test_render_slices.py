"""Slices through a regular volume (``volviz.render.slices``): orientation of the 2D images, colours through the
transfer function, and a one-line error for a slice the data cannot give."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.datasets import RegularVolume
from volviz.optics import TransferFunction
from volviz.render.slices import SliceError, slice_colors, slice_values

VOLUME = RegularVolume(np.arange(2 * 3 * 4, dtype=np.float32).reshape(2, 3, 4))   # value = 12 x + 4 y + z


def test_slice_images_run_along_the_other_axes_with_row_zero_at_the_top() -> None:
    z = slice_values(VOLUME, "z", 1)
    assert z.shape == (3, 2) and z[-1, 0] == 1 and z[0, 0] == 4 * 2 + 1 and z[-1, 1] == 12 + 1
    x = slice_values(VOLUME, "x", 1)
    assert x.shape == (4, 3) and x[-1, 0] == 12 and x[0, 2] == 12 + 8 + 3
    y = slice_values(VOLUME, "y", 2)
    assert y.shape == (4, 2) and y[-1, 1] == 12 + 8 and y[0, 0] == 8 + 3


def test_colours_are_the_tf_colours_clamped_to_its_range() -> None:
    tf = TransferFunction([10.0, 20.0], [[0.0, 0.0, 1.0], [2.0, 1.0, 0.0]], [1.0, 1.0])
    rgb = slice_colors(np.array([0.0, 10.0, 15.0, 20.0, 99.0, np.nan]), tf)
    assert rgb.tolist() == [[0, 0, 255], [0, 0, 255], [255, 128, 128], [255, 255, 0], [255, 255, 0], [0, 0, 0]]


def test_a_slice_outside_the_grid_or_of_a_mesh_is_refused_in_one_line() -> None:
    with pytest.raises(SliceError, match=r"^z slice 4 is outside the volume's 0\.\.3$"):
        slice_values(VOLUME, "z", 4)
    with pytest.raises(SliceError, match="slices need a regular volume"):
        slice_values(object(), "z", 0)


def test_drag_index_is_the_grid_index_nearest_the_mouse_ray_along_the_axis() -> None:
    """A plane grabbed at (7, 13, 5): a ray through (7, 13, 3 + 9 * 0.5) (any direction) puts the z plane at 9; a ray
    passing beside the axis line puts it at the index of the closest point; a ray beyond the grid clamps."""
    from volviz.render.slices import drag_index

    volume = RegularVolume(np.zeros((10, 12, 14), np.float32), spacing=(1.0, 2.0, 0.5), origin=(1.0, 2.0, 3.0))
    anchor = np.array([7.0, 13.0, 5.0])
    target = np.array([7.0, 13.0, 3.0 + 9 * 0.5])
    for d in ([1.0, 0.3, -0.2], [-0.5, 1.0, 0.7], [0.0, 1.0, 0.0]):
        d = np.array(d) / np.linalg.norm(d)
        assert drag_index(volume, "z", anchor, target - 20 * d, d) == 9
    # the ray x = 30, z = 3 + 6.2 * 0.5 along y: the closest point of the axis line is at z index 6.2 -> 6
    assert drag_index(volume, "z", anchor, (30.0, -50.0, 3.0 + 6.2 * 0.5), (0.0, 1.0, 0.0)) == 6
    assert drag_index(volume, "z", anchor, (7.0, -50.0, 99.0), (0.0, 1.0, 0.0)) == 13
    assert drag_index(volume, "x", anchor, (1.0 + 3 * 1.0, 13.0, -40.0), (0.0, 0.0, 1.0)) == 3
    assert drag_index(volume, "z", anchor, (7.0, 13.0, -40.0), (0.0, 0.0, 1.0)) == 4   # along the axis: stays


def test_plane_at_names_the_plane_under_a_pixel() -> None:
    """Planes x = 2 and z = 4 in an offscreen plotter: the pixel where a point of each projects picks that plane and
    the point; a corner pixel picks none."""
    from types import SimpleNamespace

    import pyvista as pv

    from volviz.render.slices import SlicesView

    volume = RegularVolume(np.arange(10 * 12 * 14, dtype=np.float32).reshape(10, 12, 14), spacing=(1.0, 2.0, 0.5),
                           origin=(1.0, 2.0, 3.0))
    tf = TransferFunction([0.0, 2000.0], [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], [1.0, 1.0])
    plotter = pv.Plotter(off_screen=True, window_size=(300, 300))
    try:
        view = SlicesView(plotter, SimpleNamespace(id="s", settings={"z": 4, "x": 2}), volume, tf)
        plotter.view_isometric()
        plotter.reset_camera()
        plotter.render()
        renderer = plotter.renderer
        for axis, point in (("z", (7.0, 13.0, 5.0)), ("x", (3.0, 13.0, 6.0))):
            renderer.SetWorldPoint(*point, 1.0)
            renderer.WorldToDisplay()
            hit = view.plane_at(renderer, *renderer.GetDisplayPoint()[:2])
            assert hit is not None and hit[0] == axis and np.allclose(hit[1], point, atol=0.1), (axis, hit)
        assert view.plane_at(renderer, 2, 2) is None
    finally:
        plotter.close()
