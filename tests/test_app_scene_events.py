"""The window follows the scene's change events (issue #18, ``SceneController.changes``): a change made to the scene
without the docks (as an undo step, a reverted show or a script makes it) marks the session edited and shows in the
scene dock; the dock's own edits still reach the scene. Real widgets under Xvfb."""
from __future__ import annotations

import pytest
from PySide6.QtCore import Qt

from test_app_window import wait_loaded, window  # noqa: F401  (the fixture)

pytest.importorskip("PySide6")


def test_the_scene_dock_and_the_dirty_flag_follow_the_scene(qtbot, window) -> None:  # noqa: F811
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    controller, tree = window.controller, window.scene_tree
    comp = tree.current_component()
    assert comp is not None and controller.component(comp).visible
    window.set_dirty(False)

    controller.set_opacity(comp, 0.3, update=False)            # not through the dock
    assert window.dirty and "*" in window.windowTitle()
    assert tree.opacity.value() == 30
    assert tree.item(comp).data(0, Qt.ItemDataRole.UserRole + 1) == pytest.approx(0.3)

    window.set_dirty(False)
    controller.set_visible(comp, False, nature=False, build=False)
    assert window.dirty
    assert tree.item(comp).checkState(0) == Qt.CheckState.Unchecked

    tree.item(comp).setCheckState(0, Qt.CheckState.Checked)      # the dock's own edit reaches the scene
    assert controller.component(comp).visible
    assert tree.item(comp).checkState(0) == Qt.CheckState.Checked
    tree.opacity.setValue(70)
    assert controller.component(comp).opacity == pytest.approx(0.7)
