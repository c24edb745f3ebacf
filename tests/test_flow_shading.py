"""Issue #28's shading on regular volumes in the real window: the component's Shading box ticked in the settings
form lights the volume, the session saves it, and ``volviz render`` of the saved session draws the same picture."""
from __future__ import annotations

import json

import numpy as np
from PySide6.QtCore import QPoint, Qt

from conftest import data_file
from flows import compare_with_render, screen, wait_loaded, wait_settled


def test_shading_box_lights_the_volume_as_volviz_render_does(qtbot, make_window, tmp_path) -> None:
    """neghip: unlit at first (matches the render); the Shading box clicked: the volume property is lit, the picture
    changes (RMSE > 5 against the unlit one), the saved session has ``shade`` true, and the screen matches ``volviz
    render`` of it (RMSE < 1.5)."""
    window = make_window()
    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    unlit = compare_with_render(window, tmp_path, "unlit")
    assert unlit["rmse"] < 1.5, unlit
    before = screen(window)
    assert not window.controller.views["data"].prop.GetProperty().GetShade()
    qtbot.waitUntil(lambda: window.scene_tree.form is not None and "shade" in window.scene_tree.form.rows)
    box = window.scene_tree.form.editor("shade")
    window.scene_dock.raise_()
    qtbot.waitUntil(box.isVisible)
    assert not box.isChecked()
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton, pos=QPoint(8, box.height() // 2))   # on the box itself
    assert box.isChecked()
    qtbot.waitUntil(lambda: window.controller.component("data").settings.get("shade") is True, timeout=20000)
    wait_settled(qtbot, window)
    prop = window.controller.views["data"].prop.GetProperty()
    assert prop.GetShade() == 1 and (prop.GetAmbient(), prop.GetDiffuse(), prop.GetSpecular()) == (0.3, 0.7, 0.2)
    change = float(np.sqrt(np.mean((screen(window) - before) ** 2)))
    assert change > 5.0, change        # the lighting changed the picture
    lit = compare_with_render(window, tmp_path, "lit")
    saved = json.loads((tmp_path / "lit.json").read_text())
    assert saved["components"][0]["settings"]["shade"] is True
    assert lit["rmse"] < 1.5 and lit["off"] < 0.002, lit
