"""``volviz.render.image_overlay.ImageOverlay`` keeps one vtkImageData from image to image and changes it in place
(origin, dimensions, a new scalar array; issue #28, VTK objects changed without a new time stamp): VTK re-uploads
its texture only when the data's time stamp passes the upload. Each image shown after another, of the same size and
of another size (a preview's), is the one on screen, pixel for pixel."""
from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from volviz.render.image_overlay import ImageOverlay  # noqa: E402

SIZE = (64, 48)


def _image(w: int, h: int, seed: int) -> np.ndarray:
    """An opaque RGBA8 image of random colours (every pixel differs from another seed's)."""
    img = np.random.default_rng(seed).integers(0, 256, (h, w, 4), dtype=np.uint8)
    img[..., 3] = 255
    return img


def test_each_image_shown_after_another_is_the_one_drawn() -> None:
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("black")
    overlay = ImageOverlay(pl)
    try:
        for seed in range(3):                                   # the same size: only the scalars change
            img = _image(*SIZE, seed)
            overlay.show(img)
            assert np.array_equal(pl.screenshot(return_img=True)[..., :3], img[..., :3]), f"image {seed}"
        small = _image(SIZE[0] // 4, SIZE[1] // 4, 7)           # another size: dimensions and origin too
        overlay.show(small)
        blocks = np.repeat(np.repeat(small, 4, axis=0), 4, axis=1)
        assert np.array_equal(pl.screenshot(return_img=True)[..., :3], blocks[..., :3])
        again = _image(*SIZE, 8)                                # and back to the window's size
        overlay.show(again)
        assert np.array_equal(pl.screenshot(return_img=True)[..., :3], again[..., :3])
    finally:
        overlay.remove()
        pl.close()
