"""The scalar bar's title sits over the bar (``volviz.render.decorations._place_title``, issue #28): the title's
pixels and the bar's color strip's overlap in x, at the window sizes people use and with a long title that must
move left to stay in the window. Before, the title was right-aligned at 98 % of the width, 60-100 pixels right of
the bar (x 850-887 over a bar at 760-787 in the app's viewport)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import data_file

LONG = "Nodal displacement magnitude of the notch (log)"


def _screenshot(size: tuple[int, int], title: str | None) -> np.ndarray:
    """neghip.slc's first look rendered offscreen at ``size``, the scalar bar's title set to ``title`` (None: the
    array's name); (H, W, 3) int."""
    from volviz.render.controller import SceneController
    from volviz.render.offscreen import offscreen_plotter
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

    session = data_session(data_file("volumes/neghip.slc"))
    session.render.options.update(axes=False, outline=False)
    if title is not None:
        session.render.options["scalar_bar_style"] = {"title": title}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        datasets = load_datasets(session, None)
    plotter = offscreen_plotter(size)
    try:
        SceneController(plotter, session, datasets).build()
        return np.asarray(plotter.screenshot(None, return_img=True)).astype(int)
    finally:
        plotter.close()


def _extents(image: np.ndarray) -> tuple[tuple[int, int], tuple[int, int]]:
    """The x extents (first, last column) of the bar's color strip (saturated pixels in the right fifth of the
    image) and of the title (grey text pixels in the rows above the strip's top; the top label's upper half may be
    among them, but the labels lie right of the strip, so only the title can overlap it)."""
    h, w = image.shape[:2]
    right = image[:, int(0.8 * w):]
    saturated = (right.max(axis=2) - right.min(axis=2)) > 40
    rows, cols = np.nonzero(saturated)
    strip = (int(cols.min()) + int(0.8 * w), int(cols.max()) + int(0.8 * w))
    top = int(rows.min())
    background = image[0, 0]
    above = image[max(0, top - 40):top - 2]
    grey = (above.max(axis=2) - above.min(axis=2) < 12) & (np.abs(above - background).sum(axis=2) > 150)
    tcols = np.nonzero(grey.any(axis=0))[0]
    assert tcols.size, "no title pixels above the bar"
    return strip, (int(tcols.min()), int(tcols.max()))


@pytest.mark.parametrize("size", [(905, 740), (1280, 740), (1920, 1080)])
@pytest.mark.parametrize("title", [None, LONG])
def test_the_title_sits_over_the_bar(size: tuple[int, int], title: str | None) -> None:
    image = _screenshot(size, title)
    strip, text = _extents(image)
    print(size, title, "strip", strip, "title", text)
    assert text[0] <= strip[1] and strip[0] <= text[1], f"title x {text} does not overlap the bar's x {strip}"
    assert text[1] < size[0] - 2, f"the title runs off the window: x {text}"
    if title is None:      # a short title starts at the strip's left edge
        assert abs(text[0] - strip[0]) <= 3, f"title x {text}, bar x {strip}"
