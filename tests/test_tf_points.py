"""``volviz.optics.tf_points``: where the TF editor's control points go when one is added, moved or removed."""
from __future__ import annotations

import numpy as np

from volviz.optics.tf_points import MIN_POINTS, insert_point, moved_scalar, remove_point

SCALARS = np.array([0.0, 10.0, 20.0])
COLORS = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
EXTINCTION = np.array([0.0, 2.0, 4.0])


def test_an_inserted_point_takes_the_functions_color_there() -> None:
    scalars, colors, extinction, i = insert_point(SCALARS, COLORS, EXTINCTION, 15.0, 1.5)
    assert i == 2
    assert scalars.tolist() == [0.0, 10.0, 15.0, 20.0]
    assert colors.tolist() == [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [1.0, 0.5, 0.5], [1.0, 1.0, 1.0]]
    assert extinction.tolist() == [0.0, 2.0, 1.5, 4.0]
    assert SCALARS.tolist() == [0.0, 10.0, 20.0] and len(COLORS) == 3  # the given arrays are left as they were


def test_an_inserted_point_goes_between_the_end_points() -> None:
    """Beyond the ends (the view may span the histogram's wider range) it still goes after the first point and
    before the last one, with the end's color: the ends keep the range."""
    scalars, colors, extinction, i = insert_point(SCALARS, COLORS, EXTINCTION, -5.0, 1.0)
    assert i == 1 and scalars.tolist() == [0.0, -5.0, 10.0, 20.0] and colors[1].tolist() == [0.0, 0.0, 1.0]
    scalars, colors, extinction, i = insert_point(SCALARS, COLORS, EXTINCTION, 25.0, 1.0)
    assert i == 2 and scalars.tolist() == [0.0, 10.0, 25.0, 20.0] and colors[2].tolist() == [1.0, 1.0, 1.0]
    assert extinction.tolist() == [0.0, 2.0, 1.0, 4.0]
    _, _, _, i = insert_point(SCALARS, COLORS, EXTINCTION, 0.0, 1.0)
    assert i == 1


def test_an_interior_point_moves_between_its_neighbours_and_the_ends_keep_the_range() -> None:
    eps = 1e-9 * 20.0
    assert moved_scalar(SCALARS, 1, 12.5) == 12.5
    assert moved_scalar(SCALARS, 1, 30.0) == 20.0 - eps
    assert moved_scalar(SCALARS, 1, -3.0) == 0.0 + eps
    assert moved_scalar(SCALARS, 0, 5.0) == 0.0
    assert moved_scalar(SCALARS, 2, 5.0) == 20.0
    assert moved_scalar(np.array([0.0, 0.25, 0.5]), 1, 1.0) == 0.5 - 1e-9  # a range under 1: eps is 1e-9


def test_removing_a_point() -> None:
    scalars, colors, extinction = remove_point(SCALARS, COLORS, EXTINCTION, 1)
    assert scalars.tolist() == [0.0, 20.0]
    assert colors.tolist() == [[0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]
    assert extinction.tolist() == [0.0, 4.0]
    assert MIN_POINTS == 2
