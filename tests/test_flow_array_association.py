"""A name on both the points and the cells is offered once for each and draws the one chosen (issue #28): the
OpenFOAM cavity's Array list showed "U" and "p" twice, nothing told them apart, and either item showed the point
array (the spec was the bare name). Now the cell items read "U:magnitude (cells)" and choosing one draws the cell
array, on the screen and in ``volviz render`` of the saved session."""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt

from conftest import data_file
from flows import (assert_matches_render, changed_share, pick_combo_item, scalar_bar_ranges, screen, wait_loaded,
                   wait_settled)


def _texts(combo) -> list[str]:
    return [combo.itemText(i) for i in range(combo.count())]


def _drawn_range(series, spec: str) -> tuple[float, float]:
    """The range over the time steps of the point scalar ``spec`` draws (``volviz.model.arrays.select_array``)."""
    from volviz.model.arrays import select_array

    values = [select_array(series.frame(i), spec).point_data[spec] for i in range(len(series))]
    return min(float(v.min()) for v in values), max(float(v.max()) for v in values)


def test_the_cavity_shows_the_cell_velocity_it_is_asked_for(qtbot, make_window, tmp_path) -> None:
    """case.foam one time step on (t = 0.5; at t = 0 the cells are at rest), then Array -> "U:magnitude (cells)"
    and "U:0 (cells)" picked with clicks in the combo's popup: every item's text is distinct, the setting names the
    cell array, the transfer function and scalar bar take the range over the time steps of the cell array averaged
    onto the points (up to 0.852; the point array reaches 1: the lid's points move at 1), the picture changes, and
    it matches ``volviz render`` of the saved session within the flow tests' bounds."""

    window = make_window()
    window.resize(900, 650)
    window.open_path(data_file("ecosystem/openfoam-cavity/case.foam"))
    wait_loaded(qtbot, window)
    window.timeline_dock.raise_()
    qtbot.mouseClick(window.timeline.forward_button, Qt.MouseButton.LeftButton)
    wait_settled(qtbot, window)
    assert window.controller.time == 0.5
    combo = window.scene_tree.array
    texts = _texts(combo)
    assert len(set(texts)) == len(texts), texts
    assert {"p (points)", "p (cells)", "U:magnitude (points)", "U:0 (cells)"} <= set(texts), texts
    comp = window.controller.session.components[0].id
    assert window.controller.component(comp).settings.get("array") in (None, "U:magnitude")
    points_shown = screen(window)
    series = window.datasets[window.controller.component(comp).dataset]

    pick_combo_item(qtbot, combo, "U@cells:magnitude")
    qtbot.waitUntil(lambda: window.controller.component(comp).settings.get("array") == "U@cells:magnitude",
                    timeout=20000)
    wait_settled(qtbot, window)
    assert combo.currentText() == "U:magnitude (cells)"
    lo, hi = _drawn_range(series, "U@cells:magnitude")
    assert lo == 0.0 and 0.85 < hi < 0.86, (lo, hi)       # the cells' magnitude, not the points' 0 .. 1
    tf_lo, tf_hi = window.controller.transfer_function(comp).range
    assert np.isclose(tf_lo, lo, rtol=1e-3) and np.isclose(tf_hi, hi, rtol=1e-3), (tf_lo, tf_hi)
    assert any(np.allclose(r, (lo, hi), rtol=1e-3) for r in scalar_bar_ranges(window)), scalar_bar_ranges(window)
    assert changed_share(points_shown, screen(window)) > 0.01
    assert_matches_render(window, tmp_path, "cells-magnitude")

    pick_combo_item(qtbot, combo, "U@cells:0")
    qtbot.waitUntil(lambda: window.controller.component(comp).settings.get("array") == "U@cells:0", timeout=20000)
    wait_settled(qtbot, window)
    lo, hi = _drawn_range(series, "U@cells:0")
    tf_lo, tf_hi = window.controller.transfer_function(comp).range
    assert np.isclose(tf_lo, lo, rtol=1e-3) and np.isclose(tf_hi, hi, rtol=1e-3), (tf_lo, tf_hi, lo, hi)
    assert_matches_render(window, tmp_path, "cells-component")


def test_a_spec_worded_otherwise_selects_the_item_that_names_it() -> None:
    """A session may name an array as the list does not (``p@points``; ``U`` for the magnitude): the combo selects
    the item of that array and component instead of listing the spec once more."""
    from volviz.io import read
    from volviz.model.arrays import list_arrays
    from volviz_app.array_choice import offered_spec

    infos = list_arrays(read(data_file("ecosystem/openfoam-cavity/case.foam")).frame(1))
    assert offered_spec("p@points", infos) == "p" and offered_spec("p@cells", infos) == "p@cells"
    assert offered_spec("U@points", infos) == offered_spec("U", infos) == "U:magnitude"
    assert offered_spec("U@cells:mag", infos) == "U@cells:magnitude" and offered_spec("U:1", infos) == "U:1"
    assert offered_spec("q", infos) == "q" and offered_spec("U:7", infos) == "U:7"   # not offered: kept as given
