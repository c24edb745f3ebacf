"""Sorting for the next camera in the background (volviz.unstructured.prefetch)."""
from __future__ import annotations

import numpy as np

from volviz.optics import TransferFunction
from volviz.unstructured import synthetic as syn
from volviz.model.camera import Camera
from volviz.unstructured.prefetch import SortPrefetcher, render_path, same_view
from volviz.unstructured.render import render

TF = TransferFunction([0.0, 0.3, 0.6, 0.9], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], [0.0, 3.0, 6.0, 1.0])


def test_render_path_equals_separate_renders_and_uses_background_sorts():
    m = syn.cavity_box(6)                                # non-convex: boundary relations enter the sort
    cams = [Camera.orbit(m.points, a, 25, 2.4) for a in (10, 40, 70)]
    frames = list(render_path(m, TF, cams, (40, 32)))
    for cam, (img, st) in zip(cams, frames):
        assert np.array_equal(img, render(m, TF, cam, (40, 32), "pt"))
        assert st.extra["sort_prefetched"] is True
        assert st.extra["background_sort_s"] > 0.0


def test_prefetch_for_another_view_is_not_used():
    m = syn.box_tets(4)
    a, b = Camera.orbit(m.points, 10, 25, 2.4), Camera.orbit(m.points, 11, 25, 2.4)
    with SortPrefetcher(m) as pre:
        pre.prefetch(a, (40, 32))
        assert pre.take(b, (40, 32)) is None                  # another camera
        assert pre.take(a, (41, 32)) is None                  # another image size
        res = pre.take(a, (40, 32))
        assert res is not None and sorted(res.order.tolist()) == list(range(m.n_cells))
        assert pre.take(a, (40, 32)) is None                  # handed out once
        assert (pre.hits, pre.misses) == (1, 3)


def test_same_view_ignores_clipping_range_and_unnormalised_view_up():
    c = Camera((3.0, 1.0, 2.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 30.0, clipping_range=(0.1, 10.0))
    # up scaled and tilted along the view direction: the same orthonormal frame
    d = Camera((3.0, 1.0, 2.0), (0.0, 0.0, 0.0), (-1.2, -0.4, 1.2), 30.0, clipping_range=(1.0, 50.0))
    assert same_view(c, d, (64, 48), (64, 48))
    assert not same_view(c, d, (64, 48), (48, 64))
    e = Camera((3.0, 1.0, 2.0 + 1e-6), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 30.0)
    assert not same_view(c, e, (64, 48), (64, 48))
