"""The GPU PT pass (``volviz.render.gl_pt.GLPTVolume``) refills its visibility order in place between frames (issue
#28, VTK objects changed without a new time stamp): as VTK's index buffer, 32-bit cells in NumPy arrays kept from
frame to frame and shared with VTK (``volviz.unstructured.index_buffer``; VTK rebuilds the buffer only when the poly
data's time stamp passes the last build), or as the order texture (uploaded when the pass marks it dirty). One
volume drawn for camera after camera (and back to the first) draws, in each frame, the pixels of a new volume drawn
once for that camera, both ways. Negative control (the index buffer refilled in the shared memory without a new
array or ``Modified``, patched in a script): the second and fourth frames drew the previous camera's order (932 and
982 of 1280 pixels off); with new arrays handed to VTK and no ``Modified`` they followed (the ``Modified`` in
``_set_index_buffer`` is not what keeps them right, the new arrays are)."""
from __future__ import annotations

import numpy as np
import pytest

from test_render_gl_pt import TF, _gl_image, _plotter
from volviz.model.camera import Camera
from volviz.render.gl_pt import GLPTVolume
from volviz.unstructured import synthetic as syn

SIZE = (40, 32)


@pytest.mark.parametrize("order_texture", [False, True], ids=["index-buffer", "order-texture"])
def test_each_frame_draws_the_order_refilled_for_its_camera(order_texture: bool) -> None:
    mesh = syn.cavity_box(6)                 # a cavity: a stale order draws other pixels
    cams = [Camera.orbit(mesh.points, a, 20, 2.5) for a in (30, 110, 30, 200)]
    fresh = [_gl_image(mesh, TF, cam, SIZE, order_texture=order_texture) for cam in cams]
    assert not np.array_equal(fresh[0], fresh[1]) and np.array_equal(fresh[0], fresh[2])
    pl = _plotter(SIZE, cams[0])
    vol = GLPTVolume(pl, mesh, TF, order_texture=order_texture)
    try:
        orders = []
        for k, cam in enumerate(cams):
            cam.apply_to(pl.renderer.GetActiveCamera())
            pl.ren_win.Render()
            assert vol.stats["sorted"], f"frame {k} did not sort for its camera"
            orders.append(vol.order.copy())
            assert np.array_equal(pl.screenshot(return_img=True), fresh[k]), f"frame {k} drew another order"
        assert not np.array_equal(orders[0], orders[1])
    finally:
        vol.remove()
        pl.close()
