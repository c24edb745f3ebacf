"""The natural scene's fog and cloud overlay is a premultiplied texture on a quad spanning the viewport
(``NatureView._set_overlay``, issue #28): an image of the viewport's size is drawn pixel for pixel (C + (1 - α) B),
and a smaller one (a preview while the camera moves or flies, drawn into a frame of any size) covers the whole
viewport, magnified by OpenGL's linear filter without colour bleeding from transparent texels. Before, a
``vtkImageMapper`` drew the image one pixel per pixel from the viewport's corner, so previews were magnified on the
CPU (PIL, 34 ms per 990x673 preview) and a frame drawn at another size than the image showed a part of it."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.render.nature_view import _overlay_rgba, _viewport_quad

SIZE = (96, 64)
BACKGROUND = (0.2, 0.5, 0.7)


@pytest.fixture()
def plotter():
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=SIZE)
    pl.ren_win.SetMultiSamples(0)   # as the app and ``volviz render`` on a software rasteriser (image_overlay)
    pl.set_background(BACKGROUND)
    pl.add_mesh(pv.Sphere(radius=0.5), color="orange", lighting=False)
    yield pl
    pl.close()


def _drawn(plotter, premultiplied: np.ndarray | None, smooth: bool = False) -> np.ndarray:
    """The plotter's frame (row 0 at the top, float 0..255) with ``premultiplied`` (H, W, 4 floats, row 0 at the top)
    as the overlay (None: none)."""
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    actor = None
    if premultiplied is not None:
        rgba8 = _overlay_rgba(premultiplied)
        image = vtk.vtkImageData()
        image.SetDimensions(rgba8.shape[1], rgba8.shape[0], 1)
        image.GetPointData().SetScalars(numpy_to_vtk(rgba8.reshape(-1, 4), deep=True))
        actor = _viewport_quad(image)
        actor.GetTexture().SetInterpolate(smooth)
        plotter.add_actor(actor, reset_camera=False, render=False)
    plotter.render()
    frame = plotter.screenshot().astype(float)
    if actor is not None:
        plotter.remove_actor(actor, render=False)
    return frame


def test_an_overlay_of_the_viewports_size_is_drawn_pixel_for_pixel(plotter) -> None:
    """Random premultiplied colours and opacities, a band of pure emission (α = 0, shown with α' = max colour) and a
    transparent band: the frame is C + (1 - α') B of the frame without overlay, within the 8-bit rounding (a texel
    one pixel off would be off by up to 255)."""
    rng = np.random.default_rng(7)
    w, h = SIZE
    alpha = rng.random((h, w))
    color = rng.random((h, w, 3)) * alpha[..., None]
    alpha[:8], color[:8] = 0.0, 0.0                 # transparent
    alpha[8:16], color[8:16] = 0.0, 0.3             # emission
    image = np.concatenate([color, alpha[..., None]], axis=-1)
    scene = _drawn(plotter, None)
    shown = _drawn(plotter, image)
    shown_alpha = np.maximum(alpha, color.max(axis=-1))[..., None]
    expected = 255.0 * color + (1.0 - shown_alpha) * scene
    err = np.abs(shown - expected)
    assert err.max() <= 1.5, err.max()
    assert np.array_equal(shown[:8], scene[:8])     # nothing drawn where the overlay is transparent


def test_a_smaller_overlay_is_magnified_over_the_viewport(plotter) -> None:
    """A quarter-size image (a preview), linearly filtered: its left half an opaque red ramp, its right half
    transparent. The ramp covers the left half of the viewport and rises in steps of 1/4 of a texel per pixel; the
    right half beyond the texel at the edge shows the scene exactly, with no red bled into it."""
    w, h = SIZE[0] // 4, SIZE[1] // 4
    image = np.zeros((h, w, 4))
    image[:, : w // 2, 0] = np.linspace(0.1, 0.9, w // 2)[None, :]
    image[:, : w // 2, 3] = 1.0
    scene = _drawn(plotter, None)
    shown = _drawn(plotter, image, smooth=True)
    left = shown[:, 2: SIZE[0] // 2 - 2, 0]                  # inside the ramp (its first and last half texels clamp)
    steps = np.diff(left, axis=1)
    ramp_step = 255.0 * 0.8 / (w // 2 - 1) / 4            # one texel's rise over 4 pixels
    assert np.all(np.abs(steps - ramp_step) <= 1.5), (steps.min(), steps.max(), ramp_step)
    assert np.all(shown[:, : SIZE[0] // 2 - 2, 1:] == 0)    # opaque red: the scene hidden, green and blue 0
    beyond = slice(SIZE[0] // 2 + 2, SIZE[0])               # past the half texel blended with the ramp's edge
    assert np.array_equal(shown[:, beyond], scene[:, beyond])


def test_the_overlay_texture_holds_premultiplied_colour() -> None:
    """``_overlay_rgba``: colour never above opacity (a filtered texel cannot carry colour from a transparent one),
    emission shown with its largest channel as opacity, rows bottom-up."""
    image = np.zeros((2, 3, 4))
    image[0, 0] = (0.2, 0.1, 0.0, 0.5)     # top row
    image[1, 1] = (0.4, 0.0, 0.0, 0.0)     # emission
    image[1, 2] = (2.0, 0.0, 0.0, 1.5)     # out of range: clipped
    rgba8 = _overlay_rgba(image)
    assert rgba8.dtype == np.uint8 and rgba8.shape == (2, 3, 4)
    assert np.all(rgba8[..., :3] <= rgba8[..., 3:])
    assert rgba8[1, 0].tolist() == [51, 26, 0, 128]       # the top row last (VTK's order)
    assert rgba8[0, 1].tolist() == [102, 0, 0, 102]
    assert rgba8[0, 2].tolist() == [255, 0, 0, 255]
    assert rgba8[0, 0].tolist() == [0, 0, 0, 0]
