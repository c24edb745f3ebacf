"""Every array of a dataset is offered and any one can be shown (volviz.model.arrays): specs, listings with ranges
and non-finite counts, the default choice, and the selection of scalars, components, magnitudes and cell arrays."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import data_file
from volviz.model import CurvilinearGrid, RegularVolume, TimeSeries, UnstructuredMesh, VTK_HEXAHEDRON
from volviz.model.arrays import ArraySpec, default_array, list_arrays, parse_array_spec, select_array


def test_specs_parse_and_print_back():
    assert parse_array_spec("T") == ArraySpec("T")
    assert parse_array_spec("V:2") == ArraySpec("V", 2)
    assert parse_array_spec("V:magnitude") == parse_array_spec("V:mag") == ArraySpec("V", "magnitude")
    assert parse_array_spec("a:b") == ArraySpec("a:b")          # a colon inside a name stays in the name
    assert str(parse_array_spec("Nodal Displacement:1")) == "Nodal Displacement:1"
    for bad in ("", "  ", "V:9"):
        with pytest.raises(ValueError):
            parse_array_spec(bad)


def _hex_mesh() -> UnstructuredMesh:
    """Two unit cubes side by side: a point vector, a point scalar and a cell scalar."""
    pts = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1, 2)], float)
    hexes = np.array([[0, 1, 4, 3, 6, 7, 10, 9], [1, 2, 5, 4, 7, 8, 11, 10]])
    vec = np.stack([pts[:, 0], 2 * pts[:, 1], np.zeros(len(pts))], axis=1)
    flat = np.full(len(pts), 5.0)
    return UnstructuredMesh(pts, [(VTK_HEXAHEDRON, hexes)], {"flat": flat, "v": vec}, {"c": np.array([1.0, 3.0])})


def test_listing_ranges_components_and_choices():
    infos = {i.name: i for i in list_arrays(_hex_mesh())}
    assert infos["v"].association == "point" and infos["v"].components == 3
    assert infos["v"].choices == ["v:magnitude", "v:0", "v:1", "v:2"]
    assert infos["v"].range == pytest.approx((0.0, np.sqrt(8.0)))
    assert infos["flat"].range == (5.0, 5.0) and not infos["flat"].varies
    assert infos["c"].association == "cell" and infos["c"].range == (1.0, 3.0)


def test_default_is_first_varying_array_and_vectors_show_their_magnitude():
    mesh = _hex_mesh()
    assert default_array(mesh) == "v:magnitude"        # "flat" is active (first) but constant
    shown = select_array(mesh, None)
    assert shown.active == "v:magnitude"
    assert np.allclose(shown.point_data["v:magnitude"], np.linalg.norm(mesh.point_data["v"], axis=1))


def test_components_and_cell_arrays_become_point_scalars():
    mesh = _hex_mesh()
    one = select_array(mesh, "v:1")
    assert np.array_equal(one.point_data["v:1"], 2 * mesh.points[:, 1])
    cells = select_array(mesh, "c")
    # VTK's cell-to-point filter: the mean of the cells around each point
    expected = np.where(mesh.points[:, 0] == 0, 1.0, np.where(mesh.points[:, 0] == 2, 3.0, 2.0))
    assert np.allclose(cells.point_data["c"], expected)
    with pytest.raises(ValueError, match="the arrays are: flat, v, c"):
        select_array(mesh, "pressure")
    with pytest.raises(ValueError, match="3 components"):
        select_array(mesh, "v:5")


def test_nonfinite_values_are_counted():
    data = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    data[0, 0, 0] = np.nan
    data[1, 2, 3] = np.inf
    vol = RegularVolume(data, name="d")
    (info,) = list_arrays(vol)
    assert info.nonfinite == 2 and info.range == (1.0, 22.0)


def test_curvilinear_grid_vectors_and_time_series():
    pts = np.stack(np.meshgrid(np.arange(3.0), np.arange(2.0), np.arange(2.0), indexing="ij"), axis=-1)
    grid = CurvilinearGrid(pts, {"m": pts.copy()}, cell_data={"k": np.array([[[2.0]], [[4.0]]])})
    assert select_array(grid, "m:0").point_data["m:0"].shape == (3, 2, 2)
    series = TimeSeries([0.0, 1.0], [grid, grid])
    chosen = select_array(series, "m:2")
    assert isinstance(chosen, TimeSeries) and np.array_equal(chosen.frame(1).point_data["m:2"], pts[..., 2])
    assert {i.name for i in list_arrays(series)} == {"m", "k"}


def test_real_files_offer_every_array():
    from volviz.io import read

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fin = read(data_file("bluntfin/bluntfinxyz.bin"))
        notch = read(data_file("ecosystem/notch_disp.vtu"))
    names = [i.name for i in list_arrays(fin)]
    assert names[:3] == ["Density", "Momentum", "StagnationEnergy"] and len(names) == 13
    assert default_array(fin) == "Density"
    assert default_array(notch) == "Nodal Displacement:magnitude"     # the vector-only mesh of the issue


def test_vertex_colors_of_meshes():
    """A mesh's own colours as bytes: red/green/blue arrays (signed bytes as meshio reads PLY's unsigned ones, or
    floats in [0, 1]) or one RGB(A) array; none for a mesh of data arrays, and never a default array."""
    from volviz.model import UnstructuredMesh
    from volviz.model.arrays import default_array, vertex_colors

    points = np.zeros((3, 3))
    cells = [(1, np.arange(3).reshape(-1, 1))]
    signed = {"red": np.array([-1, 0, 127], np.int8), "green": np.array([-128, 5, 6], np.int8),
              "blue": np.array([1, 2, 3], np.int8)}
    mesh = UnstructuredMesh(points, cells, point_data=dict(signed))
    np.testing.assert_array_equal(vertex_colors(mesh), [[255, 128, 1], [0, 5, 2], [127, 6, 3]])
    assert default_array(mesh) is None
    unit = UnstructuredMesh(points, cells, point_data={"Red": np.array([0.0, 0.5, 1.0]),
                                                       "Green": np.zeros(3), "Blue": np.ones(3),
                                                       "Alpha": np.ones(3)})
    np.testing.assert_array_equal(vertex_colors(unit), [[0, 0, 255, 255], [128, 0, 255, 255], [255, 0, 255, 255]])
    rgb = UnstructuredMesh(points, cells, point_data={"RGB": np.array([[1, 2, 3]] * 3, np.uint8),
                                                      "t": np.array([1.0, 2.0, 3.0])})
    np.testing.assert_array_equal(vertex_colors(rgb), [[1, 2, 3]] * 3)
    assert default_array(rgb) == "t"
    assert vertex_colors(UnstructuredMesh(points, cells, point_data={"t": np.ones(3)})) is None
