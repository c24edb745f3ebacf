"""Clipping a time series of meshes while its steps change, in the real window (issue #28: every flow ends in the
right picture). A PT volume's cut is made on a worker from the whole mesh of the step shown when it started; when
the step changes before the cut is shown, the cut is made again from the new step's mesh (``SceneEdits.
cut_in_background``). Before, the old step's cut was shown over the new step until the next step.
"""
from __future__ import annotations

import numpy as np

from flows import assert_matches_render, open_settled, wait_settled
from volviz.model.clip import ClipPlane, ClipSettings


def test_a_cut_made_of_the_previous_step_is_made_again_of_the_step_shown(qtbot, make_window, tmp_path) -> None:
    """The mesh shown is the last step's cut, and the picture ``volviz render`` makes of the saved session."""
    window = open_settled(qtbot, make_window, "ecosystem/openfoam-cavity", (700, 500))
    controller = window.controller
    view = controller.pt_volume("data")
    lo, hi = (np.asarray(v) for v in (view.whole_mesh.points.min(axis=0), view.whole_mesh.points.max(axis=0)))
    middle = 0.5 * (lo + hi)
    clip = ClipSettings(planes=(ClipPlane(tuple(middle), (1.0, 0.0, 0.0)),))   # keeps x >= the middle
    controller.session.set_clip(clip)
    # the clipping's cut starts on a worker from step 0's mesh; the last step is shown before it is done (the
    # order a slow cut and a quick step give; the cut's end runs on this thread after this test code returns)
    window.scene_edits.cut_in_background(controller, controller.clip, ["data"])
    last = window.timeline.steps[-1]
    frame = controller.blend_volume("data", last)
    assert controller.show_volumes({"data": frame}) == []
    qtbot.waitUntil(window.scene_edits.clipping_shown, timeout=30000)
    wait_settled(qtbot, window)
    assert view.whole_mesh is frame.whole, "the step shown changed"
    shown = view.mesh
    assert shown.points[:, 0].min() >= middle[0] - 1e-9 * (hi[0] - lo[0])
    np.testing.assert_array_equal(np.sort(shown.scalars), np.sort(frame.shown.scalars))   # the last step's cut
    window.timeline.set_time(last)                                   # the display time the session saves
    qtbot.waitUntil(lambda: window.volume_time_shown is not None and window.volume_time_shown[0] == last,
                    timeout=30000)
    wait_settled(qtbot, window)
    print("screen vs volviz render:", assert_matches_render(window, tmp_path, "cavity-clipped"))
