"""Dataset model conventions: VTK point order, image orientation, time-series interpolation."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model import Image2D, RegularVolume, TimeSeries
from volviz.model.timeseries import bracket, frame_at


def test_regular_volume_to_pyvista_keeps_x_fastest() -> None:
    data = np.arange(2 * 3 * 4, dtype=np.float32).reshape(2, 3, 4)
    grid = RegularVolume(data, spacing=(1, 2, 3), origin=(5, 0, 0)).to_pyvista()
    assert grid.dimensions == (2, 3, 4)
    assert grid.point_data["scalars"][grid.find_closest_point((6, 4, 9))] == data[1, 2, 3]


def test_image_row_zero_is_north() -> None:
    data = np.array([[10, 11, 12], [20, 21, 22]], dtype=np.uint8)  # row 0 = top of the file = north
    grid = Image2D(data, spacing=(1.0, 5.0), origin=(100.0, 200.0)).to_pyvista()
    assert grid.point_data["values"][grid.find_closest_point((100, 205, 0))] == 10  # north-west corner
    assert grid.point_data["values"][grid.find_closest_point((102, 200, 0))] == 22  # south-east corner


def test_bad_shapes_are_refused() -> None:
    with pytest.raises(ValueError, match="3D"):
        RegularVolume(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="spacing"):
        RegularVolume(np.zeros((2, 2, 2)), spacing=(1, 0, 1))
    with pytest.raises(ValueError, match="increase"):
        TimeSeries([1.0, 1.0], [None, None])


def test_time_series_interpolation() -> None:
    frames = [RegularVolume(np.full((2, 2, 2), v, dtype=np.uint8)) for v in (0, 100, 200)]
    series = TimeSeries([1.0, 2.0, 4.0], frames)
    assert bracket(series, 3.0) == (1, 2, 0.5)
    assert bracket(series, 0.0) == (0, 0, 0.0) and bracket(series, 9.0) == (2, 2, 0.0)
    assert np.all(frame_at(series, 3.0).data == 150.0)
    assert np.all(frame_at(series, 1.25).data == 25.0)
    assert np.all(frame_at(series, 3.0, interpolate=False).data == 100)
    assert frame_at(series, 2.0).data.dtype == np.uint8  # exactly on a step: the step itself


def test_a_moving_mesh_is_interpolated_in_its_positions_too() -> None:
    """Steps of one topology whose points move (a deforming surface): between steps the points are blended as the
    values are, in float64 (coordinates near 1e6 keep their precision); a step with other cells keeps the earlier
    step's points (no blend across a remeshing)."""
    from volviz.model.datasets import UnstructuredMesh

    tri = [(5, np.array([[0, 1, 2]]))]
    p0 = np.array([[1e6, 0.0, 0.0], [1e6 + 1.0, 0.0, 0.0], [1e6, 1.0, 0.0]])
    steps = [UnstructuredMesh(p0 + [0.0, 0.0, z], tri, {"v": np.full(3, z, np.float32)}) for z in (0.0, 2.0)]
    mid = frame_at(TimeSeries([0.0, 1.0], steps), 0.25)
    assert mid.points.dtype == np.float64 and np.array_equal(mid.points, p0 + [0.0, 0.0, 0.5])
    assert np.array_equal(mid.point_data["v"], np.full(3, 0.5, np.float32))
    other = UnstructuredMesh(p0 + [0.0, 0.0, 2.0], [(5, np.array([[0, 2, 1]]))], {"v": np.full(3, 2.0, np.float32)})
    kept = frame_at(TimeSeries([0.0, 1.0], [steps[0], other]), 0.25)
    assert np.array_equal(kept.points, p0) and np.array_equal(kept.point_data["v"], np.full(3, 0.5, np.float32))


def test_height_field_bilinear_height() -> None:
    from volviz.nature.heightfield import HeightField

    h = np.zeros((3, 3))
    h[1, 1] = 4.0
    field = HeightField(h, spacing=(2.0, 2.0), origin=(10.0, 20.0))
    assert field.height_at(12.0, 22.0) == 4.0
    assert field.height_at(11.0, 22.0) == 2.0
    assert field.height_at(-100.0, 22.0) == 0.0  # clamped to the grid


def test_histogram_of_a_series_covers_every_step() -> None:
    from volviz.model.stats import histogram

    frames = [RegularVolume(np.full((2, 2, 2), v, dtype=np.uint8)) for v in (0, 0, 200)]
    counts, edges = histogram(TimeSeries([0.0, 1.0, 2.0], frames), bins=4)
    assert edges[0] == 0 and edges[-1] == 200
    assert counts.tolist() == [16, 0, 0, 8]
