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
