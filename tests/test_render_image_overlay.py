"""volviz images drawn over a real offscreen PyVista plotter (volviz.render.image_overlay): every pixel lands where
it belongs, including the top row and the right column (the image actor spans its first to last point, so without
the one-pixel border those two were dropped), half transparency blends with the straight-alpha "over", and the last
overlay removed gives the plotter its multisampling back."""
from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from volviz.render.image_overlay import ImageOverlay, unpremultiply_rgba8  # noqa: E402

SIZE = (40, 30)


def _pattern(w: int, h: int) -> np.ndarray:
    """Opaque RGBA8 whose every pixel tells its row and column."""
    img = np.zeros((h, w, 4), np.uint8)
    img[..., 0] = (np.arange(w) * 6)[None, :]
    img[..., 1] = (np.arange(h) * 8)[:, None]
    img[..., 2] = 200
    img[..., 3] = 255
    return img


def test_every_pixel_lands_in_place_including_the_top_row_and_right_column() -> None:
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("black")
    overlay = ImageOverlay(pl)
    img = _pattern(*SIZE)
    overlay.show(img)
    shot = pl.screenshot(return_img=True)
    assert shot.shape[:2] == (SIZE[1], SIZE[0])
    assert np.array_equal(shot[..., :3], img[..., :3])
    overlay.visible = False
    assert not pl.screenshot(return_img=True)[..., :3].any()
    pl.close()


def test_half_transparent_image_blends_over_the_scene_and_msaa_comes_back() -> None:
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("white")
    samples = pl.ren_win.GetMultiSamples()
    overlay = ImageOverlay(pl)
    assert pl.ren_win.GetMultiSamples() == 0
    premult = np.zeros((SIZE[1], SIZE[0], 4))
    premult[..., 0] = 0.5                                   # half-opaque pure red, premultiplied
    premult[..., 3] = 0.5
    overlay.show(unpremultiply_rgba8(premult))
    shot = pl.screenshot(return_img=True)[..., :3].astype(int)
    # over white: C = (0.5, 0, 0) + 0.5 (1, 1, 1) = (1, 0.5, 0.5)
    assert np.abs(shot - np.array([255, 128, 128])).max() <= 1
    overlay.remove()
    assert pl.ren_win.GetMultiSamples() == samples
    pl.close()


def test_the_image_is_blended_without_order_independent_transparency_over_translucent_geometry() -> None:
    """The image is one translucent layer: VTK's order-independent transparency (its default) drew it through float
    targets of the window's size and a full-window resolve, most of an overlay's cost per frame on llvmpipe
    (docs/bench/flow-gaps.md, survey 15). Without it the "over" is exact, also over the scene's own translucent
    geometry (drawn by the scene's renderer, which keeps its setting)."""
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("white")
    pl.add_mesh(pv.Plane(i_size=10, j_size=10), color=(0.0, 0.0, 1.0), opacity=0.5, lighting=False)
    pl.camera_position = [(0, 0, 5), (0, 0, 0), (0, 1, 0)]
    under = pl.screenshot(return_img=True)[..., :3].astype(float)
    overlay = ImageOverlay(pl)
    assert not overlay.renderer.GetUseOIT() and pl.renderer.GetUseOIT()
    premult = np.zeros((SIZE[1], SIZE[0], 4))
    premult[..., 1] = 0.25                                  # quarter-opaque pure green, premultiplied
    premult[..., 3] = 0.25
    overlay.show(unpremultiply_rgba8(premult))
    shot = pl.screenshot(return_img=True)[..., :3].astype(float)
    assert np.abs(under - np.array([128, 128, 255])).max() <= 1    # the half-transparent blue plane over white
    assert np.abs(shot - (np.array([0, 64, 0]) + 0.75 * under)).max() <= 1.5
    pl.close()
