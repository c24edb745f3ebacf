"""``*.xyz`` is both a PLOT3D grid and a text point cloud (issue #32): the content decides. A PLOT3D grid's dimension
header must give the file's size (``plot3d.is_plot3d_grid``); a text table must parse, in at least three of four of
its first rows, or more than half of them when that is 8 rows or more (``csv_points.is_point_text``). A point cloud
whose first row is damaged was taken for PLOT3D by its name and refused in PLOT3D's words ("PLOT3D xyz header claims
1 block(s) of 540024880x..."); it now goes to the table's reader, which names the row. One whose first row is 2-5
whole numbers, a third of its rows with a field more, was taken for AVS UCD by content ("line 1 ('0 0 100') is not
the header line"): AVS UCD's sniffer now holds the lines after its header against the counts (``id x y z`` node
lines, cell lines with an AVS cell type), which a table's rows are not."""
from __future__ import annotations

import shutil

import pytest

import volviz.io as vio
from volviz.bench.robustness_formats import _xyz
from volviz.io.csv_points import is_point_text
from volviz.io.plot3d import is_plot3d_grid
from volviz.io.registry import HEAD_BYTES, spec_of
from volviz_vtk_readers.specs import is_avs_ucd


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


@pytest.mark.parametrize("first", [None, b"12 7", b"12 7 3", b"5 4 3 2 1"])
def test_a_cloud_whose_first_row_is_whole_numbers_and_a_third_of_rows_odd_is_no_avs_ucd(cloud, first):
    """The seed (first row ``0 0 100``, or 2, 3 or 5 whole numbers) with a fourth field on every third row (26 rows):
    not AVS UCD, a table, read with the odd rows (the first too, when of another width) named and left out."""
    path, rest = cloud
    rows = [b"0 0 100"] + rest.splitlines()
    rows = [first or rows[0]] + [row + b" 7" if i % 3 == 2 else row for i, row in enumerate(rows) if i]
    path.write_bytes(b"\n".join(rows) + b"\n")
    head = path.read_bytes()[:HEAD_BYTES]
    assert not is_avs_ucd(head) and is_point_text(head)
    assert spec_of(path).name == "points-text"
    kept = [row for row in rows if len(row.split()) == 3]
    first_odd = f"line 1 holds {len(first.split())}, " if first and len(first.split()) != 3 else ""
    with pytest.warns(vio.ReadWarning, match=rf"^{path}: {80 - len(kept)} of 80 rows do not hold the 3 fields most of "
                                             rf"its rows hold \({first_odd}line 3 holds 4, line 6 holds 4, "):
        mesh = vio.read(path, isolate=False)
    assert mesh.points.tolist() == [[float(v) for v in row.split()] for row in kept]


@pytest.mark.parametrize("columns, cut, holds", [(3, 28, 2), (4, 31, 1)])
def test_a_cloud_cut_in_its_third_row_is_a_table_not_plot3d(tmp_path, columns, cut, holds):
    """The campaign's cuts at byte 28 and 31 of the seeds (two rows and part of a third) were refused in PLOT3D's
    words ("PLOT3D xyz header claims 1 block(s) of ..."): the cut last row, without its line end, made one row of
    three odd for the sniffer. It is left out of the sniffer's sample now, as the reader leaves it out of the table."""
    _xyz(tmp_path, columns)
    path = tmp_path / "cloud.xyz"
    path.write_bytes(path.read_bytes()[:cut])
    assert spec_of(path).name == "points-text"
    with pytest.warns(vio.ReadWarning, match=rf"^{path}: 1 of 3 rows do not hold the {columns} fields most of its rows "
                                             rf"hold \(line 3 holds {holds}\) and are left out$"):
        mesh = vio.read(path, isolate=False)
    assert mesh.points.tolist() == [[0.0, 0.0, 100.0], [0.37, 3.5, 101.0]]
