"""The window's views follow the session's edit events (issue #31): a transfer-function point dragged in the dock is
an edit of the session, and the CPU PT view of the Blunt Fin is re-made in the background because the session
announced it (``ViewScheduler.views_follow``), not because the edit asked for a refresh; an edit made on the session
directly, as a script makes it, re-renders the window the same way. Real window, widgets and rendering under Xvfb."""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint

from flows import drag, open_blunt_fin, screen, wait_settled
from volviz.model.events import SceneChange


def test_a_tf_point_dragged_in_the_dock_re_renders_through_the_model_event(qtbot, make_window) -> None:
    window = open_blunt_fin(qtbot, make_window)
    wait_settled(qtbot, window)
    comp = window.scene_tree.current_component()
    key = f"pt:{comp}"
    assert key in window.controller.camera_views()   # a view re-made in the background, not drawn by VTK itself
    heard: list[SceneChange] = []
    window.session.changes.subscribe(heard.append)
    before, updates = screen(window), window.view_updates.get(key, 0)
    editor = window.tf_editor
    tf_before = editor.transfer_function
    index = len(tf_before) // 2
    p = editor.canvas.to_screen(tf_before.scalars[index], tf_before.extinction[index])
    start = QPoint(int(p.x()), int(p.y()))
    drag(qtbot, editor.canvas, start, QPoint(start.x(), editor.canvas._plot_rect().bottom() - 2))
    wait_settled(qtbot, window)
    after = screen(window)
    assert editor.transfer_function.extinction[index] < 0.1 * tf_before.extinction[index]
    assert heard and set(heard) <= {SceneChange("transfer_function", comp, preview)
                                    for preview in (True, False)}
    assert heard[-1] == SceneChange("transfer_function", comp)        # the finished edit, at full size
    assert window.view_updates[key] > updates
    assert (np.abs(after - before).sum(axis=2) > 10).mean() > 0.01
    assert window.dirty

    del heard[:]
    window.session.set_transfer_function(comp, tf_before)           # a script's edit: no dock, no refresh call
    wait_settled(qtbot, window)
    assert heard == [SceneChange("transfer_function", comp)]
    assert np.abs(screen(window) - before).max() <= 2.0
