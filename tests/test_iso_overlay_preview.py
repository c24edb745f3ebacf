"""The CPU isosurface overlay's preview (issue #28): the image VTK shows, a reduced-resolution preview magnified to the
window and its saturated pixels composited over the scene, is made by ``compute`` on a worker thread, and the
window shows what the old GUI-thread path showed."""
from __future__ import annotations

import threading

import numpy as np

from test_iso_overlay import _close_plotters, iso_component, scene, shot  # noqa: F401  (the fixture)
from volviz.render.image_overlay import OverlayView, overlay_rgba8
from volviz.render.iso_overlay import IsoOverlay
from volviz.render.vtk_facade import vtk_to_numpy

SCALE = 4   # the app's previews are 1 / MOVING_SCALE of the window; 4 makes blocks of 4 x 4 window pixels


def old_shown(img: np.ndarray, request: dict) -> np.ndarray:
    """What ``IsoOverlay.finish`` showed before: 3/4-pass pixels whose color exceeds their alpha composited over the
    preview's scene color and made opaque, then the whole image magnified and converted on the GUI thread."""
    shown = img.copy()
    over = np.any(img[..., :3] > img[..., 3:4] + 0.5 / 255.0, axis=-1)
    scene_rgb = request["rgb"][over].astype(np.float64) / 255.0
    shown[over, :3] = np.minimum(img[over, :3] + (1.0 - img[over, 3:4]) * scene_rgb, 1.0)
    shown[over, 3] = 1.0
    return overlay_rgba8(shown, request)


def uploaded(view: IsoOverlay) -> np.ndarray:
    """The straight-alpha RGBA8 the overlay's image actor draws, row 0 at the top, without its one-pixel border."""
    data = view._overlay.data
    w, h, _ = data.GetDimensions()
    rgba = vtk_to_numpy(data.GetPointData().GetScalars()).reshape(h, w, 4)
    return rgba[1:-1, 1:-1][::-1]


def test_preview_is_magnified_on_the_worker_and_shows_what_the_gui_thread_path_showed():
    c, p = scene([iso_component()])
    c.set_iso_mode("3pass")
    view = c.iso_overlay
    request = view.begin(scale=SCALE)
    w, h = (int(v) for v in p.ren_win.GetSize())
    assert request["preview"] and request["size"] == (w // SCALE, h // SCALE)

    made: list = []
    worker = threading.Thread(target=lambda: made.append(view.compute(request)))
    worker.start()
    worker.join()
    img, st, rgba8 = made[0]
    assert img.shape == (h // SCALE, w // SCALE, 4)
    assert rgba8.shape == (h, w, 4) and rgba8.dtype == np.uint8        # magnified to the window on the worker
    assert st.saturated_px > 0                   # the 3-pass sums exceed alpha somewhere: that path is covered too

    expected = old_shown(img, request)
    view.finish(request, img, st, rgba8)
    new_screen = shot(p)
    assert np.array_equal(uploaded(view), rgba8)                 # finish only hands the worker's image over
    assert np.abs(rgba8.astype(int) - expected).max() <= 1       # the old path's image within one level
    assert (rgba8[..., 3] > 0).mean() > 0.1                      # and the surfaces cover the window's middle
    assert view.stats["saturated_px"] == st.saturated_px and view.stats["size"] == request["size"]

    OverlayView.finish(view, request, img, st, expected)         # the old path's image in the same window
    old_screen = shot(p)
    assert np.abs(new_screen - old_screen).max() * 255 <= 1.0 + 1e-9
