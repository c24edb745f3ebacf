"""An array spec names the association of a name on both the points and the cells (issue #28,
``volviz.model.arrays``): ``NAME@cells`` / ``NAME@points`` before the component, a bare name the point array."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.arrays import ArraySpec, array_info, default_array, list_arrays, parse_array_spec, select_array


def test_specs_with_an_association_parse_and_print_back() -> None:
    assert parse_array_spec("p@cells") == ArraySpec("p", None, "cell")
    assert parse_array_spec("U@cells:0") == parse_array_spec("U:0@cells") == ArraySpec("U", 0, "cell")
    assert parse_array_spec("U@Points:mag") == ArraySpec("U", "magnitude", "point")
    assert str(ArraySpec("U", 0, "cell")) == "U@cells:0" and str(ArraySpec("p", None, "point")) == "p@points"
    # an @ that is not an association word stays in the name, as does a lone association word
    assert parse_array_spec("a@b") == ArraySpec("a@b") and parse_array_spec("@cells") == ArraySpec("@cells")
    assert parse_array_spec("e@mail:1") == ArraySpec("e@mail", 1)
    for text in ("p@cells", "U@cells:0", "U@points:magnitude", "Nodal Displacement:1", "a:b"):
        assert str(parse_array_spec(text)) == text


def _written_vtu(tmp_path):
    """A VTU of two hexahedra with a point and a cell array both named "p" (and a point-only "t"), read back."""
    import pyvista as pv

    from volviz.io import read

    grid = pv.ImageData(dimensions=(3, 2, 2)).cast_to_unstructured_grid()
    grid.point_data["p"] = np.arange(grid.n_points, dtype=np.float64)
    grid.point_data["t"] = np.full(grid.n_points, 2.0)
    grid.cell_data["p"] = np.array([10.0, 30.0])
    path = tmp_path / "both.vtu"
    grid.save(path)
    return read(path)


def test_a_vtu_name_on_points_and_cells_is_offered_and_drawn_for_each(tmp_path) -> None:
    mesh = _written_vtu(tmp_path)
    choices = [(i.name, i.association, i.choices) for i in list_arrays(mesh)]
    assert ("p", "point", ["p"]) in choices and ("p", "cell", ["p@cells"]) in choices
    assert ("t", "point", ["t"]) in choices
    assert array_info(mesh, "p@cells").range == (10.0, 30.0) and array_info(mesh, "p").range == (0.0, 11.0)
    assert default_array(mesh) == "p"
    points = select_array(mesh, "p")
    assert points.active == "p" and np.array_equal(points.point_data["p"], mesh.point_data["p"])
    assert np.array_equal(select_array(mesh, "p@points").point_data["p@points"], mesh.point_data["p"])
    cells = select_array(mesh, "p@cells")
    # VTK's cell-to-point filter: the mean of the cells around each point (x = 0: 10, x = 1: both, x = 2: 30)
    x = mesh.points[:, 0]
    assert cells.active == "p@cells"
    assert np.allclose(cells.point_data["p@cells"], np.where(x == 0, 10.0, np.where(x == 2, 30.0, 20.0)))
    assert np.array_equal(cells.point_data["p"], mesh.point_data["p"])    # the point array is left as it was
    with pytest.raises(ValueError, match=r"no cell array 't'; the arrays are: p, t, p@cells"):
        select_array(mesh, "t@cells")


def test_a_name_only_on_the_cells_keeps_its_bare_spec(tmp_path) -> None:
    """The cell-centred Tecplot zone: P is only on the cells, offered as "P", and "P@cells" names it too."""
    from conftest import data_file
    from volviz.io import read

    mesh = read(data_file("ecosystem/cellcentered.tec"))
    info = array_info(mesh, "P")
    assert info is not None and info.association == "cell" and info.choices == ["P"]
    assert array_info(mesh, "P@cells") == info and array_info(mesh, "P@points") is None
    assert np.array_equal(select_array(mesh, "P@cells").point_data["P@cells"], select_array(mesh, "P").point_data["P"])
