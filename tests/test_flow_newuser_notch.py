"""notch_disp.vtu (a CPU PT overlay, ``volviz.render.pt_prop``, and VTK's outline box) on screen and in ``volviz
render`` after an orbit (issue #28). After a mouse drag the screen showed the outline box in another pose than the
volume, and the volume cut along that box: RMSE 16.5-17.1 against the render of the saved session (4 of 4 runs),
while the camera of the last image's ``begin``, the live camera and the saved one were the same. The cause was the
preview hold's camera swap (``volviz.render.preview_hold``): ``DeepCopy`` keeps the camera's time stamp, so the
first held frame after the drag's last move computed VTK's camera matrices for a preview's camera and every later
frame re-used them. Since the swap marks the camera modified: RMSE 0.0 (3 of 3)."""
from __future__ import annotations

from conftest import data_file
from flows import assert_matches_render, drag_viewport, wait_loaded, wait_settled


def test_notch_after_an_orbit_renders_as_shown(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    window.resize(900, 650)
    window.open_path(data_file("ecosystem/notch_disp.vtu"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    print("open: screen vs volviz render:", assert_matches_render(window, tmp_path, "open"))
    drag_viewport(qtbot, window, 180, 40)
    wait_settled(qtbot, window)
    print("orbit: screen vs volviz render:", assert_matches_render(window, tmp_path, "orbit"))
