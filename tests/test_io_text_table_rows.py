"""A text point table without a header row takes its width from most of its rows (``csv_points._headerless_width``,
issue #32): the rows of another number of fields are left out with one warning naming them by line, and a table
whose rows share no width is refused."""
from __future__ import annotations

import numpy as np
import pytest

import volviz.io as vio

ROWS = [f"{i} {i % 7} {100 + i} {i % 5}" for i in range(40)]         # x y z value


def test_the_rows_most_rows_agree_with_are_read_and_the_odd_ones_named(tmp_path):
    path = tmp_path / "cloud.xyz"
    odd = {0: "0 0 100 0 9", 5: "5 5", 30: "30 2 130 0 1 2"}           # first row too: a field more
    path.write_text("\n".join(odd.get(i, row) for i, row in enumerate(ROWS)) + "\n")
    with pytest.warns(vio.ReadWarning) as caught:
        mesh = vio.read(path, isolate=False)
    assert [str(w.message) for w in caught] == [f"{path}: 3 of 40 rows do not hold the 4 fields most of its rows "
                                                "hold (line 1 holds 5, line 6 holds 2, line 31 holds 6) and are "
                                                "left out"]
    kept = [i for i in range(40) if i not in odd]
    np.testing.assert_array_equal(mesh.points, [[i, i % 7, 100 + i] for i in kept])
    np.testing.assert_array_equal(mesh.point_data["column 4"], [i % 5 for i in kept])


def test_a_warning_names_ten_odd_rows_and_counts_the_rest(tmp_path):
    path = tmp_path / "cloud.xyz"
    rows = [f"{i} {i % 7} {100 + i} {i % 5}" + (" 1" if i % 4 == 1 else "") for i in range(60)]   # 15 of 60
    path.write_text("\n".join(rows) + "\n")
    with pytest.warns(vio.ReadWarning) as caught:
        mesh = vio.read(path, isolate=False)
    named = ", ".join(f"line {2 + 4 * k} holds 5" for k in range(10))
    assert [str(w.message) for w in caught] == [f"{path}: 15 of 60 rows do not hold the 4 fields most of its rows "
                                                f"hold ({named}, 5 more) and are left out"]
    assert mesh.n_points == 45


def test_a_table_whose_rows_share_no_width_is_refused(tmp_path):
    """Read as a table (``read_text_points``: the sniffer takes such a file for no table)."""
    from volviz.io.csv_points import read_text_points

    path = tmp_path / "cloud.xyz"
    path.write_text("1 2 3\n1 2 3 4\n1 2 3 4 5\n1 2 3 4 5 6\n1 2 3\n")
    with pytest.raises(vio.ReadError, match=f"^{path}: its rows disagree in their number of fields, none shared by "
                                            r"half of the first 5 \(3 in 2, 4 in 1, 5 in 1, 6 in 1\): not a table "
                                            "of points$"):
        read_text_points(path)
