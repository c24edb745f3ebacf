"""volviz.model.extent.point_extent: the same values as numpy's min/max over axis 0."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.extent import point_extent


def test_the_extent_is_each_columns_least_and_greatest_value() -> None:
    rng = np.random.default_rng(4)
    points = rng.normal(size=(1001, 3)) * [1.0, 1e-9, 1e9]
    for pts in (points, points[::3], np.asfortranarray(points), points.astype(np.float32)):
        lo, hi = point_extent(pts)
        assert lo.dtype == hi.dtype == np.float64
        np.testing.assert_array_equal(lo, pts.min(axis=0))
        np.testing.assert_array_equal(hi, pts.max(axis=0))


def test_a_nan_coordinate_makes_its_columns_extent_nan() -> None:
    pts = np.array([[0.0, 1.0, 2.0], [np.nan, -1.0, 5.0]])
    lo, hi = point_extent(pts)
    assert np.isnan(lo[0]) and np.isnan(hi[0])
    assert list(lo[1:]) == [-1.0, 2.0] and list(hi[1:]) == [1.0, 5.0]


def test_no_points_have_no_extent() -> None:
    with pytest.raises(ValueError, match="non-empty"):
        point_extent(np.zeros((0, 3)))
