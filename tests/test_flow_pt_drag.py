"""A camera drag over the Blunt Fin in the real window, on both PT backends (issues #29 and #28).

GPU (``volviz.render.gl_pt``): every frame drawn during the drag draws a visibility order made for its own camera or
the previous frame's, never an older one; the frames' orders are made on the worker (``GLPTVolume._follow``: each
frame takes the sort the previous frame started and starts its own), none on the GUI thread. Measured per frame from
``GLPTVolume.frames`` (camera serial, order serial) while real mouse events drag the camera. Measured in a 900x650
window on llvmpipe (load average 7 on 2 cores): 24 cameras in 25 frames, every frame drew the previous frame's
camera's order, the still frame after the drag its own; the frame's wait for the worker's order median 0.7 ms,
max 19.6 ms. Negative control: with ``_follow`` patched out (only the app's order jobs) this flow also drew the
previous camera's order in every frame here, even with each sort slowed by 150 ms, so the flow did not fail before;
``_follow`` makes the rule hold by construction, and ``test_render_gl_pt``'s worker-order test shows it directly.

CPU (``volviz.render.pt_prop`` + ``volviz.render.preview_hold``): the preview image is older than the camera by the
time a preview takes (measured: previews of cameras 2, 12 and 20 shown during a 21-camera drag, so up to 10 frames
old); every frame draws the outline box with the preview's camera (drawn serial equals image serial), so the box and
the image agree, and the whole view lags the mouse by those frames instead of the box sliding off the volume.
"""
from __future__ import annotations

from PySide6.QtCore import QEvent, QPoint, QPointF, Qt

from flows import _mouse, drag, open_blunt_fin, wait_loaded, wait_settled
from volviz.render.gl_pt import GLPTVolume
from volviz.render.pt_prop import PTVolume


def test_gpu_drag_draws_no_order_older_than_the_previous_frames_camera(qtbot, make_window) -> None:
    window = open_blunt_fin(qtbot, make_window)
    old = window.controller
    window.render_settings.backend.setCurrentText("gpu")
    qtbot.waitUntil(lambda: window.controller is not old, timeout=60000)
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    gpu = next(v for v in window.controller.props.values() if isinstance(v, GLPTVolume))
    first = len(gpu.frames)
    sorted_here: list[bool] = []
    gpu.renderer.AddObserver("EndEvent", lambda *a: sorted_here.append(gpu.stats["sorted"]
                                                                       and not gpu.stats["sort_prefetched"]))
    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    drag(qtbot, canvas, centre, centre + QPoint(160, 40), steps=24)
    frames = gpu.frames[first:]
    cameras = {c for c, _ in frames}
    assert len(cameras) >= 8, f"the drag drew {len(cameras)} cameras: {frames}"
    old_orders = [(c, o) for c, o in frames if o < c - 1]
    assert not old_orders, f"frames drawn with an order older than the previous frame's camera: {old_orders}"
    from_worker = [(c, o) for c, o in frames if o == c - 1]
    assert len(from_worker) >= len(cameras) // 2, f"the worker's orders were not drawn: {frames}"
    assert not any(sorted_here), "a frame of the drag sorted on the GUI thread"
    wait_settled(qtbot, window)
    window.plotter.render()
    assert gpu.frames[-1][1] == gpu.frames[-1][0], "the still frame after the drag is not exact"


def test_cpu_drag_draws_the_box_with_the_previews_camera(qtbot, make_window) -> None:
    """CPU (issue #28): while the mouse drags the camera each frame is drawn with the camera the shown preview was
    made for (``volviz.render.preview_hold``), so the outline box and the volume image agree in every frame; the
    view lags the mouse by the preview's age instead (stated in frames by the log: live minus image serial)."""
    window = open_blunt_fin(qtbot, make_window)
    wait_settled(qtbot, window)
    cpu = next(v for v in window.controller.props.values() if isinstance(v, PTVolume))
    hold = cpu.hold
    first = len(hold.frames)
    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    held = Qt.MouseButton.LeftButton
    _mouse(canvas, QEvent.Type.MouseButtonPress, QPointF(centre), held)
    for k in range(1, 21):        # a slow drag (4 s): previews are shown while it lasts
        _mouse(canvas, QEvent.Type.MouseMove, QPointF(centre + QPoint(8 * k, 2 * k)), held)
        qtbot.wait(200)
    _mouse(canvas, QEvent.Type.MouseButtonRelease, QPointF(centre + QPoint(160, 40)), Qt.MouseButton.NoButton)
    during = hold.frames[first:]
    wait_settled(qtbot, window)
    window.plotter.render()
    frames = hold.frames[first:]
    assert len({live for live, _, _ in during}) >= 8, f"the drag drew too few cameras: {during}"
    assert len({image for _, image, _ in during}) >= 3, f"too few previews shown during the drag: {during}"
    assert all(drawn == image for _, image, drawn in frames), f"a frame drew the box off the image's camera: {frames}"
    live, image, drawn = hold.frames[-1]
    assert live == image == drawn, "the still frame after the drag is not of the live camera"
