"""``volviz.scene.datasets.shown_array`` keeps one view per array spec while its dataset lives, and keeps it off the
dataset (issue #31: no cache on another object through ``__dict__``): the dataset gains no attribute, and the views
go when the dataset goes, for every kind whose view could hold on to it (a view that is the dataset itself, a time
series whose view loads its frames through it)."""
from __future__ import annotations

import gc
import weakref
from typing import Any, Callable

import numpy as np
import pytest

from volviz.model.datasets import RegularVolume, TetMesh, TimeSeries, UnstructuredMesh
from volviz.scene.datasets import shown_array


def _volume() -> RegularVolume:
    grid = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    wind = np.stack([grid, 2 * grid, -grid], axis=-1)
    return RegularVolume(grid, name="t", arrays={"t": grid, "wind": wind})


def _mesh() -> UnstructuredMesh:
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], dtype=np.float64)
    cells = [(10, np.array([[0, 1, 2, 3], [1, 2, 3, 4]]))]     # two tetrahedra (VTK_TETRA): point 0 in the first
    return UnstructuredMesh(points, cells, point_data={"p": np.arange(5, dtype=np.float64)},   # only, 4 in the second
                            cell_data={"c": np.array([1.0, 3.0])}, active="p")


def _tets() -> TetMesh:
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    return TetMesh(points, np.array([[0, 1, 2, 3]]), np.array([0.0, 1.0, 2.0, 3.0]))


def _series() -> TimeSeries:
    def load(i: int) -> RegularVolume:
        grid = np.full((2, 2, 2), float(i), dtype=np.float32)
        return RegularVolume(grid, name="t", arrays={"t": grid, "u": grid + 10})

    return TimeSeries(np.array([0.0, 1.0, 2.0]), [load(0), None, None], loader=load)


def _frame_value(view: Any) -> float:
    return float(view.frame(2).data[0, 0, 0])


CASES: list[tuple[str, Callable[[], Any], str, Callable[[Any], object]]] = [
    ("regular volume, a vector's component", _volume, "wind:1", lambda v: float(v.data[1, 2, 3])),
    ("mesh, a cell array shown at the points", _mesh, "c", lambda v: v.point_data["c"].tolist()),
    ("tetrahedra: the view is the dataset", _tets, "scalars", lambda v: v.scalars.tolist()),
    ("time series: frames load through the view", _series, "u", _frame_value),
]
EXPECTED = {"regular volume, a vector's component": 2 * 23.0, "mesh, a cell array shown at the points":
            [1.0, 2.0, 2.0, 2.0, 3.0], "tetrahedra: the view is the dataset": [0.0, 1.0, 2.0, 3.0],
            "time series: frames load through the view": 12.0}


@pytest.mark.parametrize("name, make, spec, value", CASES, ids=[c[0] for c in CASES])
def test_one_view_per_spec_kept_off_the_dataset_and_dropped_with_it(name: str, make: Callable[[], Any], spec: str,
                                                                     value: Callable[[Any], object]) -> None:
    dataset = make()
    attributes = dict(vars(dataset))
    view = shown_array(dataset, spec)
    assert value(view) == EXPECTED[name]
    assert shown_array(dataset, spec) is view                 # made once per spec
    default = shown_array(dataset, None)
    assert shown_array(dataset, None) is default
    assert vars(dataset).keys() == attributes.keys()          # no attribute added to the dataset
    assert all(vars(dataset)[k] is attributes[k] for k in attributes)
    if isinstance(dataset, TimeSeries):                       # a frame loaded through the view stays in the series
        assert dataset.frames[2] is not None

    gone, view_gone = weakref.ref(dataset), weakref.ref(view)
    del dataset, view, default
    gc.collect()
    assert gone() is None and view_gone() is None             # the kept views held neither the dataset nor themselves


def test_a_new_dataset_at_a_collected_ones_address_gets_its_own_views() -> None:
    """Entries are keyed by identity: one dropped with its dataset never answers for a later object at that id."""
    shown = []
    for k in range(50):
        grid = np.full((2, 2, 2), float(k), dtype=np.float32)
        volume = RegularVolume(grid, name="t", arrays={"t": grid, "v": grid * 2})
        shown.append(float(shown_array(volume, "v").data[0, 0, 0]))
        del volume
    assert shown == [2.0 * k for k in range(50)]
