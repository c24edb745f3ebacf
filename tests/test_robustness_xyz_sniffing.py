"""``*.xyz`` is both a PLOT3D grid and a text point cloud (issue #32): the content decides. A PLOT3D grid's dimension
header must give the file's size (``plot3d.is_plot3d_grid``); a text table must parse, in at least three of four of
its first rows (``csv_points.is_point_text``). A point cloud whose first row is damaged was taken for PLOT3D by its
name and refused in PLOT3D's words ("PLOT3D xyz header claims 1 block(s) of 540024880x..."); it now goes to the
table's reader, which names the row."""
from __future__ import annotations

import shutil

import pytest

import volviz.io as vio
from volviz.bench.robustness_formats import _xyz
from volviz.io.csv_points import is_point_text
from volviz.io.plot3d import is_plot3d_grid
from volviz.io.registry import HEAD_BYTES, spec_of


@pytest.fixture
def cloud(tmp_path):
    """The campaign's .xyz seed (80 rows of x y z, no header) and its bytes after the first row."""
    _xyz(tmp_path, 3)
    path = tmp_path / "cloud.xyz"
    raw = path.read_bytes()
    assert raw.startswith(b"0 0 100\n0.37 3.5 101\n")
    return path, raw[raw.index(b"\n") + 1:]


@pytest.mark.parametrize("first, message", [
    (b"0 0 1x0\n", r"has empty or repeated column names in its header row: 0, 0, 1x0$"),
    (b"0 0\x10100\n", r"has no column named x for the points' x coordinate; its columns are: 0, 0\x10100;"),
    (b"0 \x000 100\n", r"is not a text table \(it holds zero bytes\)$"),
])
def test_a_point_cloud_with_a_damaged_first_row_is_refused_as_a_table(cloud, first, message):
    path, rest = cloud
    path.write_bytes(first + rest)
    assert spec_of(path).name == "points-text"
    with pytest.raises(vio.ReadError, match=f"^{path}: {message}") as caught:
        vio.read(path, isolate=False)
    assert "PLOT3D" not in str(caught.value)


@pytest.mark.parametrize("first, holds", [(b"0 0 100 5\n", 4), (b"0 0\n", 2)])
def test_a_first_row_with_a_field_more_or_less_is_the_odd_row_left_out(cloud, first, holds):
    """The table's width is the one most rows hold: the damaged first row is left out with a warning naming it,
    the other 79 rows read (the first row's width made 79 of 80 rows the odd ones; issue #32)."""
    path, rest = cloud
    path.write_bytes(first + rest)
    assert spec_of(path).name == "points-text"
    with pytest.warns(vio.ReadWarning) as caught:
        mesh = vio.read(path, isolate=False)
    assert [str(w.message) for w in caught] == [f"{path}: 1 of 80 rows do not hold the 3 fields most of its rows "
                                                f"hold (line 1 holds {holds}) and are left out"]
    assert mesh.n_points == 79
    assert mesh.points[0].tolist() == [0.37, 3.5, 101.0]


def test_the_sniffers_on_the_intact_cloud_and_a_plot3d_grid(cloud, data, tmp_path):
    path, _rest = cloud
    text = path.read_bytes()
    assert is_point_text(text) and not is_plot3d_grid(text, len(text))
    grid = data("bluntfin/bluntfinxyz.bin").read_bytes()
    assert is_plot3d_grid(grid[:HEAD_BYTES], len(grid)) and not is_point_text(grid[:HEAD_BYTES])
    assert not is_plot3d_grid(grid[:HEAD_BYTES], len(grid) - 1)    # the header no longer gives the size
    assert spec_of(path).name == "points-text" and vio.read(path, isolate=False).n_points == 80


def test_a_plot3d_grid_named_xyz_is_plot3d_and_a_cut_one_refused_in_plot3d_words(data, tmp_path):
    grid = tmp_path / "fin.xyz"
    shutil.copyfile(data("bluntfin/bluntfinxyz.bin"), grid)
    assert spec_of(grid).name == "plot3d"
    assert vio.read(grid, isolate=False).n_points == 40 * 32 * 32
    grid.write_bytes(grid.read_bytes()[:-1000])
    assert spec_of(grid).name == "plot3d"           # the only reader of the name that is not a sniffed table
    with pytest.raises(vio.ReadError, match=r"PLOT3D xyz header claims 1 block\(s\) of 40x32x32 points"):
        vio.read(grid, isolate=False)
