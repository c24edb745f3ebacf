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
