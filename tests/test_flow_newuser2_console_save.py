"""The Python console's ``session`` stays the shown one after File > Save (issue #28, found driving the app as a new
user): saving swapped the window's session for the copy it had written, so an edit typed in the console afterwards
(``session.set_opacity(...)``) changed an object the scene no longer listened to: the picture stayed, the title did
not mark it unsaved, and the next save wrote part of it (the transfer functions the copies shared) while the screen
showed none of it."""
from __future__ import annotations

import numpy as np

from flows import assert_matches_render, open_settled, screen, wait_settled
from test_flow_console import _run
from test_flow_export import save_as


def test_an_edit_typed_in_the_console_after_a_save_reaches_the_view(qtbot, make_window, tmp_path) -> None:
    """HeadMRVolume.mhd, View > Python Console, then File > Save Session As (the file typed in the dialog); in the
    console ``session.set_opacity(c, 0.3)``: the scene dock's slider reads 30, the title has its '*', the picture
    changed and matches ``volviz render`` of the session saved again; ``session`` in the console is the window's."""
    window = open_settled(qtbot, make_window, "volumes/HeadMRVolume.mhd")
    window.python_console.action.trigger()
    console = window.python_console
    qtbot.waitUntil(lambda: console.widget is not None and console.widget.isVisible(), timeout=30000)
    wait_settled(qtbot, window)
    save_as(qtbot, window, tmp_path / "head.json")
    assert not window.windowTitle().endswith("*")
    before = screen(window)
    _run(qtbot, console, "session.set_opacity(session.components[0].id, 0.3); print('SET')", "SET\n")
    wait_settled(qtbot, window)
    assert window.scene_tree.opacity.value() == 30          # before the fix: 100, the edit never reached the scene
    assert window.windowTitle().endswith("*")
    assert not np.array_equal(screen(window), before)
    assert_matches_render(window, tmp_path, "after", max_rmse=1.0, max_off=0.002)
    out = _run(qtbot, console, "print('SAME', session is window.session)", "SAME ")
    assert "SAME True" in out, out
