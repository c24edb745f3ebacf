"""A TransferFunction to and from VTK's color and opacity functions (``volviz.render.vtk_tf``): ρ = opacity / unit
distance, exact round trips, node positions merged, sampled curves for other color spaces."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.optics import TransferFunction
from volviz.render.vtk_tf import tf_from_vtk, tf_to_vtk


def make_tf() -> TransferFunction:
    return TransferFunction([0.0, 0.25, 1.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 2.0, 1.0], name="three")


def test_vtk_round_trip_uses_rho_equals_opacity_over_unit_distance():
    tf = make_tf()
    ctf, otf = tf_to_vtk(tf, unit_distance=0.5)
    assert otf.GetValue(0.25) == pytest.approx(1.0)  # opacity = ρ · unit distance = 2 · 0.5
    assert ctf.GetColor(0.25) == pytest.approx((0, 1, 0))
    back = tf_from_vtk(ctf, otf, unit_distance=0.5, name="three")
    assert back == tf


def test_from_vtk_merges_different_node_positions():
    from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
    from vtkmodules.vtkRenderingCore import vtkColorTransferFunction

    ctf = vtkColorTransferFunction()
    ctf.AddRGBPoint(0.0, 0, 0, 0)
    ctf.AddRGBPoint(10.0, 1, 1, 1)
    otf = vtkPiecewiseFunction()
    otf.AddPoint(0.0, 0.0)
    otf.AddPoint(5.0, 0.8)
    otf.AddPoint(10.0, 0.2)
    tf = tf_from_vtk(ctf, otf, unit_distance=2.0)
    np.testing.assert_allclose(tf.scalars, [0, 5, 10])
    np.testing.assert_allclose(tf.extinction, [0, 0.4, 0.1])
    np.testing.assert_allclose(tf.colors[1], [0.5, 0.5, 0.5])
    ctf.SetColorSpaceToLab()  # not linear in RGB: resampled densely
    assert len(tf_from_vtk(ctf, otf, 2.0, samples=64)) > 60
    with pytest.raises(ValueError, match="unit_distance"):
        tf_from_vtk(ctf, otf, 0.0)


def test_a_region_at_the_functions_top_value_is_drawn_opaque():
    """VTK's piecewise function without clamping counts its last node's own scalar as outside: a uniform region of
    the data exactly at the function's top drew transparent (a sphere of the data's maximum came out hollow, dotted
    where the rays' samples fell inside it). With the guard node the top is inside: VTK's value there is the last
    opacity, and a sphere of value 200 (8-bit, in 10) drawn opaque from 100 up to 200 looks as it does with the
    function running on to 300, on the CPU and the GPU ray casters, to 2 levels of 255 per pixel (before: the GPU
    drew the sphere's disc as a ring, the CPU dotted it, up to 90 levels darker)."""
    import pyvista as pv

    from volviz.render.vtk_scene import volume_prop

    ctf, otf = tf_to_vtk(make_tf(), unit_distance=0.5)
    assert otf.GetValue(1.0) == pytest.approx(0.5) and otf.GetValue(1.0 + 2e-3) == 0.0 and otf.GetValue(-1e-3) == 0.0

    axis = np.arange(-24, 25, dtype=np.float64)
    z, y, x = np.meshgrid(axis, axis, axis, indexing="ij")
    grid = pv.ImageData(dimensions=(49, 49, 49), origin=(-24.0, -24.0, -24.0))
    grid.point_data["v"] = np.where(x ** 2 + y ** 2 + z ** 2 <= 20 ** 2, 200, 10).astype(np.uint8).reshape(-1)

    def image(top: float, backend: str) -> np.ndarray:
        tf = TransferFunction([100.0, top], [(1.0, 1.0, 1.0)] * 2, [0.1, 0.1])
        plotter = pv.Plotter(off_screen=True, window_size=(160, 160))
        try:
            plotter.set_background("black")
            volume_prop(plotter, grid, True, tf, 1.0, "v", backend=backend)
            plotter.camera_position = [(0.0, 0.0, 200.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
            plotter.enable_parallel_projection()
            plotter.camera.parallel_scale = 30.0
            return plotter.screenshot(None, return_img=True)[..., :3].astype(int)
        finally:
            plotter.close()

    for backend in ("cpu", "gpu"):
        at_top, beyond = image(200.0, backend), image(300.0, backend)
        assert beyond[80, 80].min() > 200                                 # the reference: the disc is drawn
        assert np.abs(at_top - beyond).max() <= 2, backend
