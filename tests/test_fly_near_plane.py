"""The natural scene's near and far planes are the view's own (``NatureView.clipping_range``), whatever VTK's fit to
the props' bounds says (issue #28). Each fly step applies its camera through ``apply_camera``, whose
``ResetCameraClippingRange`` put the near plane at 1e-3 of a far plane that depended on where the sky dome stood:
6.3-6.5 units over Yukon on screen where ``volviz render`` of the saved session had 1.0, so a flight that ended a few
terrain cells from a hillside (91 or 93 steps of W from the session's camera) showed the hillside cut open: RMSE
20.1 / 26.9 and 6.0 / 4.0 % of the pixels off by more than 24 against the render (the CI failure of
``test_hold_w_over_yukon``: RMSE 21.8, 7.0 %)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from conftest import REPO, data_file
from volviz.optics.metrics import rmse

YUKON = REPO / "resources" / "sessions" / "yukon.json"
SIZE = (330, 224)     # the fly flow's viewport (990 x 673) at a third of its size
# where 91 steps of W from the session's camera end (app fly mode at 1366 x 768): the nearest terrain in view is about
# 5 units from the eye, inside the near plane VTK's fit gave
HILLSIDE = dict(position=(500.0, 845.37, 56.56), focal_point=(500.0, 1595.37, -153.44), view_up=(0.0, 0.0, 1.0),
                view_angle=60.0)
BEFORE = dict(HILLSIDE, position=(500.0, 809.26, 48.24), focal_point=(500.0, 1559.26, -161.76))  # 3 steps back


@pytest.fixture(scope="module")
def yukon():
    from volviz.scene.datasets import load_datasets
    from volviz.session import load

    data_file("yukon/Yukon.map.pgm")
    session = load(YUKON)
    return session, load_datasets(session, YUKON)


def test_a_flight_ending_before_a_hillside_shows_what_volviz_render_shows(yukon) -> None:
    """A flight's frame three steps before its end, its last step (VTK refits the clipping range to the props'
    bounds, the dome still where that frame was made), then the full-size frame: the same picture as ``volviz
    render`` of the session at that camera, and the clipping range is the view's whenever VTK refits it."""
    from volviz.render.export import close_scene, offscreen_scene, render_session, snapshot
    from volviz.session import CameraState

    session, datasets = yukon
    end = CameraState(**HILLSIDE)
    plotter, controller = offscreen_scene(session, datasets, SIZE)
    try:
        controller.build()                        # the session's camera
        view = controller.nature
        controller.set_camera(CameraState(**BEFORE))
        controller.set_camera(end, update=False)  # the last step: VTK refits the range to the props' bounds
        assert plotter.camera.clipping_range == pytest.approx(view.clipping_range(end.position))
        controller.update_views()                 # the full-size frame that follows the stop
        near, far = plotter.camera.clipping_range
        assert near == pytest.approx(1e-3 * 1000.0) and far >= view.dome_radius
        flown = snapshot(plotter, SIZE).astype(np.float64)
        plotter.renderer.ResetCameraClippingRange()
        assert plotter.camera.clipping_range == pytest.approx((near, far))
        view.remove()                             # a removed view leaves the range to VTK again
        assert not plotter.renderer.HasObserver("ResetCameraClippingRangeEvent")
    finally:
        close_scene(plotter, controller)
    rendered = render_session(replace(session, camera=end), YUKON, SIZE, datasets=datasets).astype(np.float64)
    err = rmse(flown / 255.0, rendered / 255.0)
    off = float((np.abs(flown - rendered).max(axis=2) > 24).mean())
    print(f"flown vs rendered: RMSE {err:.3f}, {100 * off:.4f} % off by > 24")
    assert err < 1.0 and off < 0.002, (err, off)
