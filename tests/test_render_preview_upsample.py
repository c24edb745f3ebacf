"""volviz.render.preview_upsample: a preview magnified to the window by each pixel's own opaque depth."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.render.image_overlay import block_min
from volviz.render.preview_upsample import upsample_preview


def test_upsample_preview_gives_each_window_pixel_the_preview_made_for_its_depth():
    """Nearest-depth upsampling (issue #28): a thin opaque line (depth 1) in front of a volume (no opaque depth
    behind): the line's pixels take the preview pixels cut at the line (no volume), every other pixel the volume's
    color, though its block holds the line; the old magnification gave the whole block the cut image."""
    depth = np.full((8, 12), np.inf)
    depth[:, 5] = 1.0                                                # a vertical line in the third column of blocks
    cut = block_min(depth, (6, 4))
    volume = np.array([0.2, 0.3, 0.4, 0.5])
    image = np.where(np.isfinite(cut)[..., None], 0.0, volume)      # cut at the line: nothing in front of it
    out = upsample_preview(image, cut, depth)
    assert out.shape == (8, 12, 4)
    assert np.array_equal(out[:, 5], np.zeros((8, 4)))
    off = np.ones((8, 12), bool)
    off[:, 5] = False
    assert np.allclose(out[off], volume, rtol=0.0, atol=1e-12)
    depth[:, 4] = 1.0 + 0.5 * 0.01                                   # within DEPTH_MATCH of the line: served by it
    out = upsample_preview(image, block_min(depth, (6, 4)), depth)
    assert np.array_equal(out[:, 4], np.zeros((8, 4)))


def test_upsample_preview_without_opaque_geometry_is_bilinear():
    """No opaque depth anywhere: every preview pixel serves every window pixel, the plain bilinear magnification
    (pixel centres aligned: the window's corner pixels take the preview's corner pixels)."""
    image = np.zeros((2, 2, 4))
    image[0, 1] = 1.0
    out = upsample_preview(image, np.full((2, 2), np.inf), np.full((4, 4), np.inf))
    assert np.allclose(out[..., 0], [[0, 0.25, 0.75, 1], [0, 0.1875, 0.5625, 0.75],
                                     [0, 0.0625, 0.1875, 0.25], [0, 0, 0, 0]], atol=1e-9)


def test_upsample_preview_refuses_an_image_of_another_size():
    with pytest.raises(ValueError, match="does not match its cut depth"):
        upsample_preview(np.zeros((3, 2, 4)), np.zeros((2, 2)), np.zeros((4, 4)))
