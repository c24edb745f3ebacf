"""VTK's projected tetrahedra (render method "vtk") and volviz's GPU PT pass ("pt-gl") drawn as an image in a window
of a thread of its own and shown over the scene (``volviz.render.vtk_pt_image`` through ``pt_prop``'s view; issue
#28): the picture equals the one each draws in the scene's own window, an opaque plane through the volume and a sphere in front of it
included (the opaque scene's depth is written into the image's window), and no render of it runs on the caller's
thread."""
from __future__ import annotations

import threading

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from volviz.optics import TransferFunction  # noqa: E402
from volviz.render.gl_pt import GLPTVolume  # noqa: E402
from volviz.render.image_overlay import zbuffer_to_depth  # noqa: E402
from volviz.render.pt_prop import add_pt_volume  # noqa: E402
from volviz.render.vtk_pt_image import window_z  # noqa: E402
from volviz.render.vtk_scene import make_volume, volume_input  # noqa: E402
from volviz.unstructured import synthetic as syn  # noqa: E402

TF = TransferFunction([0.0, 0.3, 0.6, 0.9], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], [0.0, 3.0, 6.0, 1.0])
SIZE = (96, 72)
SPHERE = (0.2, 0.6, 0.9)


def test_window_z_inverts_the_zbuffer_conversion() -> None:
    z = np.array([0.0, 0.25, 0.5, 0.9, 0.999, 1.0])
    for parallel in (False, True):
        depth = zbuffer_to_depth(z, (0.5, 40.0), parallel)
        np.testing.assert_allclose(window_z(depth, (0.5, 40.0), parallel), z, atol=1e-12)
    # a far plane moved out: the same eye depths lie nearer in window depth; nothing -> the far plane
    depth = np.array([0.5, 2.0, 10.0, np.inf])
    far = window_z(depth, (0.5, 80.0), False)
    np.testing.assert_allclose(far[:3], 80.0 * (depth[:3] - 0.5) / (depth[:3] * 79.5))
    assert far[3] == 1.0
    np.testing.assert_allclose(window_z(depth, (0.5, 80.0), True), [0.0, 1.5 / 79.5, 9.5 / 79.5, 1.0])


def _plotter() -> pv.Plotter:
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.ren_win.SetMultiSamples(0)
    pl.set_background("black")
    # an opaque plane y = 0.5 through the left half of the cube, and a sphere in front of the cube's right part
    pl.add_mesh(pv.Plane(center=(0.25, 0.5, 0.5), direction=(0, 1, 0), i_size=1.2, j_size=0.5),
                color=(0.8, 0.6, 0.2), lighting=False)
    pl.add_mesh(pv.Sphere(radius=0.12, center=(0.75, -0.4, 0.75)), color=SPHERE, lighting=False)
    pl.camera_position = [(0.6, -2.5, 0.9), (0.5, 0.5, 0.5), (0, 0, 1)]
    return pl


def _shot(pl: pv.Plotter) -> np.ndarray:
    return pl.screenshot(return_img=True).astype(np.float64)


@pytest.mark.parametrize("method", ["vtk", "pt-gl"])
def test_pt_drawn_off_the_callers_thread_matches_it_drawn_in_the_window(method: str) -> None:
    """VTK's projected tetrahedra ("vtk") and volviz's GPU PT pass ("pt-gl", ``volviz.render.gl_pt.GLPTVolume``)."""
    mesh = syn.box_tets(6)                                          # the unit cube
    pl = _plotter()
    try:
        opaque = _shot(pl)
        camera = pl.camera.copy()
        if method == "vtk":
            volume = make_volume(volume_input(mesh), False, TF, 1.0)
            pl.add_actor(volume, reset_camera=False)
            pl.renderer.ResetCameraClippingRange()
            pl.render()
            pl.render()                                             # (VTK's mapper: its first frame lacks cells)
            direct = _shot(pl)
            pl.remove_actor(volume)
        else:
            gl = GLPTVolume(pl, mesh, TF, lookup="auto")
            pl.renderer.ResetCameraClippingRange()
            pl.render()
            direct = _shot(pl)
            gl.remove()
        pl.camera = camera
        handle = add_pt_volume(pl, mesh, TF, method=method)
        shown = _shot(pl)
        free = ~np.isfinite(handle.depth)
        sphere = np.all(np.abs(opaque / 255.0 - np.array(SPHERE)) < 0.02, axis=-1)
        threads = handle._thread_images.gl.threads
        handle.remove()
        assert threading.get_ident() not in threads and len(threads) == 1
    finally:
        pl.close()
    assert np.abs(direct - opaque).max() > 100                      # the volume is really on screen
    err = np.abs(shown - direct)
    assert np.sqrt((err ** 2).mean()) < 1.0 and (err > 3).mean() < 0.002, (np.sqrt((err ** 2).mean()), err.max())
    # the depth is honoured: the sphere in front stays as it is, the plane cuts the cube's left half
    assert sphere.sum() > 20 and np.abs(shown[sphere] - opaque[sphere]).max() <= 2
    assert free.sum() > 500 and (~free).sum() > 500
    assert handle.stats["method"] == method and handle.stats["size"] == SIZE


def test_an_image_asked_for_after_the_view_is_removed_is_transparent_and_makes_no_window() -> None:
    """The app removes a view (a new scene, another renderer) while a worker may still compute an image of a request
    begun before: that image is not shown, so none is drawn, and no window and thread are made again for it."""
    mesh = syn.box_tets(3)
    pl = _plotter()
    try:
        handle = add_pt_volume(pl, mesh, TF, method="vtk")
        assert handle.image[..., 3].max() > 0.1
        request = handle.begin()
        handle.remove()
        img, stats, rgba8 = handle.compute(request)
        assert handle._thread_images is None and stats.method == "vtk"
        assert img.shape == (SIZE[1], SIZE[0], 4) and not img.any() and not rgba8.any()
    finally:
        pl.close()
