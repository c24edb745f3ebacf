"""Flows that change the array a component shows, in the real window (issue #28)."""
from __future__ import annotations

import numpy as np

from conftest import data_file
from flows import compare_with_render, pick_combo_item, scalar_bar_ranges, wait_loaded, wait_settled


def test_a_new_array_gets_its_own_colour_range(qtbot, make_window, tmp_path) -> None:
    """Blunt Fin, Array -> MachNumber, then -> Pressure: the transfer function, the scalar bar and the picture
    follow each array's range (they kept Density's 0.19 .. 4.98, then MachNumber's 0 .. 3.39, saturating)."""
    from volviz.model.arrays import list_arrays

    window = make_window()
    window.open_path(data_file("bluntfin/bluntfinq.bin"))
    wait_loaded(qtbot, window)
    ranges = {info.name: info.range for info in list_arrays(window.datasets["data"])}
    combo = window.scene_tree.array
    for name in ("MachNumber", "Pressure"):
        pick_combo_item(qtbot, combo, name)
        qtbot.waitUntil(lambda: window.controller.component("data").settings.get("array") == name, timeout=20000)
        wait_settled(qtbot, window)
        lo, hi = ranges[name]
        tf_lo, tf_hi = window.controller.transfer_function("data").range
        assert np.isclose(tf_lo, lo, rtol=1e-6, atol=1e-9) and np.isclose(tf_hi, hi, rtol=1e-6), (name, tf_lo, tf_hi)
        assert any(np.allclose(r, (lo, hi), rtol=1e-6) for r in scalar_bar_ranges(window)), scalar_bar_ranges(window)
        assert window.tf_editor.transfer_function.range == (tf_lo, tf_hi)
    err = compare_with_render(window, tmp_path)
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err
