"""Orbiting a time series while it plays never freezes the window (issue #28, background jobs and VTK objects).

Found by driving the window so: ``series/warping_spheres.vtkhdf`` (a surface whose points move) played with the
timeline's play button while the view was dragged round froze the window for good within 40 s (2 runs of 2;
Python stacks: the time-blend job in PyVista's ``vtk_points`` under ``scene_builder.time_input``, the GUI thread
in a render). The job made the surface's VTK objects on its worker, holding the GIL, while the GUI thread's render
collected the previous surface, a PyVista object whose clean-up needs the GIL: the deadlock of the terrain in
b9391d2. The job now hands over the blended frame (arrays) and the GUI thread makes its VTK input.

A freeze cannot fail a check on the GUI thread (it is the frozen one): ``faulthandler`` ends the process with every
thread's stack after ``HANG_S``. The rule part runs the job's callable on a thread of its own and asserts it made no
VTK object and hands over none (``vtk_threads``)."""
from __future__ import annotations

import faulthandler
import sys
import time

from PySide6.QtCore import Qt

from conftest import data_file
from flows import assert_matches_render, drag_viewport, wait_loaded, wait_settled
from vtk_threads import on_worker, vtk_objects_in

#: how long the flow may take before it counts as frozen (it takes 20-40 s on the 2-core test machine)
HANG_S = 240
#: how long the view is dragged round while the series plays
PLAY_S = 20.0


def test_orbiting_a_playing_surface_series_keeps_the_window_alive(qtbot, make_window, tmp_path) -> None:
    """Play, drag left and right for ``PLAY_S`` seconds, stop: the display time moved on during the drags, the
    window settles, and its picture matches ``volviz render`` of the saved session (the flow tests' bounds)."""
    window = make_window()
    window.resize(900, 650)
    window.open_path(data_file("series/warping_spheres.vtkhdf"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    controller = window.controller
    (comp_id,) = controller.time_volumes()

    # the rule: the time job's callable makes no VTK object off the GUI thread and hands over none
    frame, calls = on_worker(lambda: controller.blend_volume(comp_id, 0.5))
    assert calls == [], calls[:5]
    assert vtk_objects_in(frame) == []

    faulthandler.dump_traceback_later(HANG_S, exit=True, file=sys.stderr)
    try:
        window.timeline_dock.raise_()
        qtbot.mouseClick(window.timeline.play_button, Qt.MouseButton.LeftButton)
        times, start, n = set(), time.monotonic(), 0
        while time.monotonic() - start < PLAY_S:
            drag_viewport(qtbot, window, -60 if n % 2 else 60, 10)
            times.add(controller.time)
            n += 1
        qtbot.mouseClick(window.timeline.play_button, Qt.MouseButton.LeftButton)
        wait_settled(qtbot, window)
    finally:
        faulthandler.cancel_dump_traceback_later()
    assert len(times) > 3, times
    assert_matches_render(window, tmp_path, "played")
