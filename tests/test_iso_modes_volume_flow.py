"""The note's 3-pass mode with a regular volume in the real window (issue #28): a session of a translucent plane
isosurface through a ball-shaped volume (``iso_volume_scene``) opened, orbited by a drag and its volume's transfer
function edited; after each step the screen is the exact composite "volume in front, surface, volume behind" of the
window's own renders (``test_iso_modes_volume.errors``), and at the end it matches ``volviz render`` of the saved
session."""
from __future__ import annotations

from flows import assert_matches_render, drag_viewport, wait_loaded, wait_settled
from iso_volume_scene import session, write_datasets
from test_iso_modes_volume import errors
from volviz.session import save


def _holds(window, step: str) -> None:
    e = errors(window.controller, window.plotter, "3pass")
    print(step, e)
    assert e["share"] > 0.05                      # the surface is in view
    # within 3 levels but where GL's edge rule and the CPU rasteriser's give the plane's outline pixels differently
    # (the reference's volume is cut by GL's plane, the overlay's surface is the CPU's; 2 of 459,398 pixels here)
    assert e["rmse"] < 1.0 and e["over3"] <= 1e-4 * e["pixels"], (step, e)
    assert e["old_rmse"] > 5.0                     # the surface over the whole volume would be far off


def open_plane_in_ball(qtbot, make_window, tmp_path, mode: str = "3pass"):
    """A window with the session of ``iso_volume_scene`` in ``mode`` opened and settled (3-pass: the CPU overlay)."""
    path = tmp_path / "plane_in_ball.json"
    save(session("auto", mode, write_datasets(tmp_path)), path)
    window = make_window()
    window.open_path(path)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    assert window.controller.iso_view is not None
    assert window.controller.iso_view.backend == ("cpu" if mode in ("2pass", "3pass", "4pass") else "gpu")
    return window


def test_three_pass_surface_lies_inside_the_volume_through_orbit_and_transfer_function_edit(qtbot, make_window,
                                                                                           tmp_path) -> None:
    """Measured in the 1400x900 window on llvmpipe, over the surface's pixels: RMSE 0.4-0.5 levels after opening,
    after a 150-px orbit and after the volume's extinction is made four times larger (the overlay made again: it holds
    the volume in front of the surface; 30.7 without that); the surface over the whole volume 27-67."""
    window = open_plane_in_ball(qtbot, make_window, tmp_path)
    _holds(window, "opened")

    drag_viewport(qtbot, window, 150, 40)
    wait_settled(qtbot, window)
    _holds(window, "orbited")

    tf = window.controller.transfer_function("vol")
    window.session.set_transfer_function("vol", tf.scaled_extinction(4.0))   # as the editor's finished edit
    wait_settled(qtbot, window)
    _holds(window, "denser volume")

    print("screen vs volviz render:", assert_matches_render(window, tmp_path, "plane_in_ball", 1.5, 0.002))
