"""Isosurfaces added, edited and removed from the Isosurfaces dock, in the real window (issue #28)."""
from __future__ import annotations

import json

from PySide6.QtCore import Qt

from conftest import data_file
from flows import assert_matches_render, changed_share, compare_with_render, open_and_show_dock, pick_combo_item, \
    screen, wait_loaded, wait_settled

VALUE = 120.0


def _iso(window):
    return next((c for c in window.controller.session.components if c.type == "isosurface"), None)


def _type(qtbot, spin, text: str) -> None:
    """Select the spin box's text with the keyboard and type ``text`` and Enter, as a user does."""
    spin.setFocus()
    qtbot.keyClick(spin, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(spin, text)
    qtbot.keyClick(spin, Qt.Key.Key_Return)


def _select_row(qtbot, table, row: int) -> None:
    rect = table.visualItemRect(table.item(row, 0))
    qtbot.mouseClick(table.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())


def _surface_share(window) -> float:
    """The share of the viewport's pixels that the isosurface's translucent actors change by more than 3 levels
    (the frame with them and without them, nothing else changed)."""
    actors = window.controller.props[_iso(window).id].volviz_translucent
    assert actors
    shown = screen(window)
    for actor in actors:
        actor.SetVisibility(False)
    try:
        bare = screen(window)
    finally:
        for actor in actors:
            actor.SetVisibility(True)
        window.plotter.render()
    return changed_share(shown, bare, levels=3.0)


def _rebuilt(qtbot, window, test) -> None:
    qtbot.waitUntil(lambda: window.controller is not None and test(), timeout=60000)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)


def test_add_edit_remove_and_undo_an_isosurface(qtbot, make_window, tmp_path) -> None:
    """neghip: type a value, Add: the scene gets an isosurface component with that value (the TF's colour there);
    select it, type an opacity, Apply: the translucent surface shows inside the volume; choose the 3-pass mode;
    Remove: the component goes; Edit > Undo brings it back with its opacity; the screen matches ``volviz render`` of
    the saved session."""
    window = make_window()
    without = open_and_show_dock(qtbot, window, data_file("volumes/neghip.slc"), window.iso_dock)
    dock = window.iso_tool.dock

    _type(qtbot, dock.value, f"{VALUE:g}")
    qtbot.mouseClick(dock.add_button, Qt.MouseButton.LeftButton)
    _rebuilt(qtbot, window, lambda: _iso(window) is not None)
    iso = _iso(window)
    assert iso.dataset == "data" and [s["value"] for s in iso.settings["styles"]] == [VALUE]
    tf = window.controller.transfer_function("data")
    rgb, _ = tf.evaluate(VALUE)
    assert all(abs(a - b) <= 0.5 / 255 for a, b in zip(iso.settings["styles"][0]["color"], rgb))
    assert dock.table.rowCount() == 1 and dock.table.item(0, 0).text() == "120"
    assert window.controller.views[iso.id].meshes and len(window.controller.views[iso.id].meshes[0].triangles) > 1000

    _select_row(qtbot, dock.table, 0)
    _type(qtbot, dock.opacity, "0.3")
    qtbot.mouseClick(dock.apply_button, Qt.MouseButton.LeftButton)
    _rebuilt(qtbot, window, lambda: _iso(window).settings["styles"][0]["opacity"] == 0.3)
    assert _iso(window).settings["styles"][0]["value"] == VALUE
    # in VTK's own mode the translucent surface is depth-peeled with the volume (volviz.render.volume_peeling): it lies
    # between the volume behind it and in front of it. Against the same frame with only the surface's actors hidden
    # (same ray caster), 0.14 % of the viewport's pixels (1024x805) changed by > 3 levels before (the whole volume was
    # composited over the surface), 3.1 % after; the peeled screen matches ``volviz render`` (RMSE 0.62)
    assert window.session.render.options.get("iso_mode", "vtk") == "vtk"
    peeled = _surface_share(window)
    print("pixels the translucent surface changes in VTK's mode:", peeled)
    assert peeled > 0.015, peeled
    print("peeled screen vs volviz render:", assert_matches_render(window, tmp_path, "peeled", 1.5, 0.002))

    pick_combo_item(qtbot, dock.mode, "3pass")
    _rebuilt(qtbot, window, lambda: window.session.render.options.get("iso_mode") == "3pass")
    assert window.controller.iso_view is not None and window.controller.iso_view.mode == "3pass"

    _select_row(qtbot, dock.table, 0)
    qtbot.mouseClick(dock.remove_button, Qt.MouseButton.LeftButton)
    _rebuilt(qtbot, window, lambda: _iso(window) is None)
    assert dock.table.rowCount() == 0

    window.action_undo.trigger()
    _rebuilt(qtbot, window, lambda: _iso(window) is not None)
    assert _iso(window).settings["styles"][0]["opacity"] == 0.3 and dock.table.rowCount() == 1

    # both frames single-sampled (llvmpipe): the translucent surface, coloured as the TF at its value, changes
    # ~1.2 % of the pixels by more than 1 level; the 3-level share of 0.8 % measured before counted the outline's
    # multisampled edges, which the surface's single-sample pass had changed
    change = changed_share(screen(window), without, levels=1.0)
    stats = window.controller.iso_stats()
    print("pixels changed by the surface:", change, "iso stats:", stats)
    n = sum(len(m.triangles) for m in window.controller.views[_iso(window).id].meshes)
    assert stats["method"].startswith("iso 3pass") and stats["triangles_drawn"] == 2 * n, stats  # drawn in 3 passes
    assert change > 0.004, change                    # and it shows (a light, translucent surface in the volume)
    err = compare_with_render(window, tmp_path)
    print("screen vs volviz render:", err, "change from the bare volume:", change)
    saved = json.loads((tmp_path / "flow.json").read_text())
    assert saved["render"]["options"]["iso_mode"] == "3pass"
    assert [c["settings"]["styles"][0]["opacity"] for c in saved["components"] if c["type"] == "isosurface"] == [0.3]
    assert err["rmse"] < 1.5 and err["off"] < 0.002, err
