"""Reduced-resolution frames of the GPU PT pass while the camera moves (issue #29; ``volviz.render.reduced_fill``,
``GLPTVolume.set_interactive``), on llvmpipe offscreen.

An interactive frame draws the cells into a float target of at most ``interactive_pixels`` pixels and upsamples it
bilinearly over the window: it must equal the exact reference rendered at the reduced size and upsampled the same
way (RMSE <= 1, max <= 4 in 8-bit units, the still frame's bounds), its target must have the reduced size, and the
still frame after it must be the frame from before, bit for bit. Measured here (llvmpipe, Mesa 22.3, VTK 9.7): the
jittered box 160x120 drawn at 80x60, RMSE 0.26 / max 0.89 against the upsampled reference (2.2 / 39 against its still
frame: sharp cell edges); the Blunt Fin at 256^2 drawn at 128^2 (the scale of a 3840x2160 drag under the 1080p cap)
0.46 / 1.76 against the upsampled reference and 0.31 / 18 against its still frame (the bench states it at 3840x2160);
with an opaque sphere in the box, on the sphere's pixels (3 pixels inside its silhouette) 0.52 / 3 against the still
frame (multisampled window: 0.62 / 6), 24 / 58 when the segments do not stop at the reduced opaque depth.
"""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv
from scipy.ndimage import binary_erosion

import test_render_gl_pt as gl_tests
from volviz.model.camera import Camera
from volviz.render.gl_pt import GLPTVolume
from volviz.render.reduced_fill import reduced_size, scaled_rays
from volviz.unstructured import synthetic as syn
from volviz.unstructured.render import render

TF, RMSE, MAX = gl_tests.TF, gl_tests.RMSE, gl_tests.MAX   # the still frames' TF and bounds
bluntfin = gl_tests.bluntfin                     # the Blunt Fin and its TF (a module fixture)
_plotter = gl_tests._plotter


def _err(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    d = a[..., :3].astype(np.float64) - b[..., :3].astype(np.float64)
    return float(np.sqrt((d ** 2).mean())), float(np.abs(d).max())


def _upsample(img: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """Bilinear upsampling of an (h', w', c) image to ``size`` = (w, h) at pixel centres with clamped edges (what
    the resolve's ``texture()`` does with a linear, clamp-to-edge target)."""
    h0, w0 = img.shape[:2]
    w, h = size
    x = np.clip((np.arange(w) + 0.5) * w0 / w - 0.5, 0.0, w0 - 1.0)
    y = np.clip((np.arange(h) + 0.5) * h0 / h - 0.5, 0.0, h0 - 1.0)
    x0, y0 = np.minimum(x.astype(int), w0 - 2), np.minimum(y.astype(int), h0 - 2)
    fx, fy = (x - x0)[None, :, None], (y - y0)[:, None, None]
    rows = img[y0] * (1.0 - fy) + img[y0 + 1] * fy
    return rows[:, x0] * (1.0 - fx) + rows[:, x0 + 1] * fx


def _drawn(pl: pv.Plotter) -> np.ndarray:
    pl.ren_win.Render()
    return pl.screenshot(return_img=True).astype(np.float64)


def test_reduced_size_caps_the_pixels_and_keeps_small_windows():
    assert reduced_size((3840, 2160)) == (1920, 1080)
    assert reduced_size((1920, 1080)) == (1920, 1080)
    assert reduced_size((800, 600)) == (800, 600)
    assert reduced_size((2560, 1440)) == (1920, 1080)
    w, h = reduced_size((1001, 777), 100_000)
    assert w * h <= 100_000 and (w, h) == (358, 278)
    assert reduced_size((5000, 1), 10) == (10, 1) and reduced_size((2, 5000), 10) == (1, 10)
    with pytest.raises(ValueError, match="window size must be positive"):
        reduced_size((0, 10))


@pytest.mark.parametrize("parallel", [False, True])
def test_scaled_rays_are_the_rays_of_the_smaller_image(parallel):
    """Drawn at half size with the window's aspect, the re-expressed basis is exactly ``Camera.rays`` at that size."""
    cam = Camera.orbit(np.array([[0.0, 0, 0], [1, 2, 3]]), 30, 20, 2.5, parallel=parallel)
    got = scaled_rays(cam.rays((64, 48), origin=(1, 0, 0)), (64, 48), (32, 24)).as_array()
    want = cam.rays((32, 24), origin=(1, 0, 0)).as_array()
    assert np.allclose(got, want, rtol=0, atol=1e-12)
    same = cam.rays((64, 48))
    assert np.array_equal(scaled_rays(same, (64, 48), (64, 48)).as_array(), same.as_array())


def test_interactive_frame_is_drawn_small_and_upsampled():
    """A jittered box 160x120 with an interactive cap of 80x60: the float target is 80x60, the screen is the exact
    reference at 80x60 upsampled (within the still frame's bounds), and the still frame afterwards is bit for bit
    the one from before the interaction (and within its bounds of the full-size reference)."""
    mesh = syn.box_tets(6, jitter=0.3)
    cam = Camera.orbit(mesh.points, 30, 20, 2.5)
    size, small = (160, 120), (80, 60)
    pl = _plotter(size, cam)
    vol = GLPTVolume(pl, mesh, TF)
    vol.interactive_pixels = small[0] * small[1]
    still = _drawn(pl)
    assert vol.target_size == size and vol.drawn_size == size
    vol.set_interactive(True)
    moving = _drawn(pl)
    assert vol.target_size == small and vol.drawn_size == small
    vol.set_interactive(False)
    again = _drawn(pl)
    assert vol.target_size == size
    vol.remove()
    pl.close()
    assert np.array_equal(again, still)
    ref = np.clip(render(mesh, TF, cam, size, "reference")[..., :3], 0.0, 1.0) * 255.0
    e_still = _err(still, ref)
    assert e_still[0] <= RMSE and e_still[1] <= MAX, e_still
    ref_small = np.clip(render(mesh, TF, cam, small, "reference")[..., :3], 0.0, 1.0) * 255.0
    e = _err(moving, _upsample(ref_small, size))
    assert e[0] <= RMSE and e[1] <= MAX, e
    assert _err(moving, still)[0] > 0.5          # it is another image: the upsampled one


def test_window_update_rate_marks_the_interaction():
    """By default the volume follows VTK's interactive marking: the window's desired update rate (a drag sets the
    interactor's, 15-30 frames/s; its end the still rate, 0.0001), as VTK's interactor styles do."""
    mesh = syn.box_tets(3)
    pl = _plotter((300, 200), Camera.orbit(mesh.points, 30, 20, 2.5))
    vol = GLPTVolume(pl, mesh, TF)
    vol.interactive_pixels = 150 * 100
    pl.ren_win.SetDesiredUpdateRate(15.0)
    _drawn(pl)
    assert vol.is_interactive() and vol.target_size == (150, 100)
    pl.ren_win.SetDesiredUpdateRate(0.0001)
    _drawn(pl)
    assert not vol.is_interactive() and vol.target_size == (300, 200)
    vol.set_interactive(False)                   # a plain switch overrides the window's rate
    pl.ren_win.SetDesiredUpdateRate(15.0)
    _drawn(pl)
    assert vol.target_size == (300, 200)
    vol.remove()
    pl.close()


def test_a_trackball_drag_draws_small_frames_and_the_release_a_full_one():
    """A mouse drag through VTK's trackball camera style (real interactor events): every render while the button is
    held draws at the reduced size, the render at the release at the window's (the style sets the window's update
    rate to the interactor's desired rate, then to its still rate before the last render)."""
    from volviz.render.vtk_facade import vtk

    mesh = syn.box_tets(3)
    pl = _plotter((300, 200), Camera.orbit(mesh.points, 30, 20, 2.5))
    iren = vtk.vtkRenderWindowInteractor()
    iren.SetRenderWindow(pl.ren_win)
    iren.SetInteractorStyle(vtk.vtkInteractorStyleTrackballCamera())
    vol = GLPTVolume(pl, mesh, TF)
    vol.interactive_pixels = 150 * 100
    _drawn(pl)                                   # the still frame before the drag
    drawn: list[tuple[int, int] | None] = []
    pl.renderer.AddObserver("EndEvent", lambda *args: drawn.append(vol.target_size))
    iren.SetEventInformation(150, 100)
    iren.LeftButtonPressEvent()
    for x in (160, 170, 180):
        iren.SetEventInformation(x, 100)
        iren.MouseMoveEvent()
    iren.LeftButtonReleaseEvent()
    vol.remove()
    pl.close()
    assert drawn == [(150, 100)] * 3 + [(300, 200)]


@pytest.mark.parametrize("samples", [0, 4])
def test_interactive_frame_stops_at_opaque_geometry(samples):
    """An opaque sphere inside the box: the interactive frame's segments end at the nearest sample of the opaque
    depth (a scaled depth blit from the window's depth copy, also when the window is multisampled), so inside the
    sphere's silhouette it stays close to the still frame; the still frame after it is unchanged."""
    mesh = syn.box_tets(6, jitter=0.3)
    cam = Camera.orbit(mesh.points, 30, 20, 2.5)
    size = (160, 120)
    pl = _plotter(size, cam, samples)
    pl.add_mesh(pv.Sphere(radius=0.3, center=(0.5, 0.5, 0.5), theta_resolution=32, phi_resolution=32),
                color=(0.8, 0.7, 0.6), lighting=False)
    vol = GLPTVolume(pl, mesh, TF, keep_multisampling=bool(samples))
    vol.interactive_pixels = 80 * 60
    still = _drawn(pl)
    vol.set_interactive(True)
    moving = _drawn(pl)
    assert vol.target_size == (80, 60)
    vol.set_interactive(False)
    again = _drawn(pl)
    vol.remove()
    pl.close()
    assert np.array_equal(again, still)
    # on the sphere (inside its silhouette) the volume in front of it is smooth: the segments must stop at it, else
    # its pixels would get the whole box behind it (module docstring)
    sphere = binary_erosion(np.abs(still - _plain_box(mesh, cam, size)).max(axis=2) > 8.0, iterations=3)
    assert sphere.sum() > 500
    e = _err(moving[sphere], still[sphere])
    assert e[0] <= 1.5, e


def _plain_box(mesh, cam, size) -> np.ndarray:
    pl = _plotter(size, cam)
    vol = GLPTVolume(pl, mesh, TF)
    img = _drawn(pl)
    vol.remove()
    pl.close()
    return img


def test_bluntfin_interactive_frame_at_half_scale(bluntfin):
    """The Blunt Fin at 256^2 drawn at 128^2 (the scale of a 3840x2160 drag under the 1080p cap): the screen is the
    reference at 128^2 upsampled, within the still bounds, and its error against the still frame stays under the
    stated bound (module docstring)."""
    mesh, tf = bluntfin
    cam = Camera.orbit(mesh.points, 40, 25, 1.6, up=(0, 0, 1))
    size, small = (256, 256), (128, 128)
    pl = _plotter(size, cam)
    vol = GLPTVolume(pl, mesh, tf)
    vol.interactive_pixels = small[0] * small[1]
    still = _drawn(pl)
    vol.set_interactive(True)
    moving = _drawn(pl)
    assert vol.target_size == small
    vol.remove()
    pl.close()
    ref_small = np.clip(render(mesh, tf, cam, small, "reference")[..., :3], 0.0, 1.0) * 255.0
    e = _err(moving, _upsample(ref_small, size))
    assert e[0] <= RMSE and e[1] <= MAX, e
    e_still = _err(moving, still)
    assert e_still[0] <= 1.0, e_still
