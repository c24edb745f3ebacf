"""Helpers of the tests of still frames drawn in strips (tests/test_flow_still_strips.py,
tests/test_flow_interaction_end.py): neghip in a window whose still frames are always drawn in strips, and the check
that the frame the strips left is the whole frame."""
from __future__ import annotations

import numpy as np

from flows import open_settled
from volviz.optics.metrics import rmse
from volviz.render import strips as strips_module

SIZE = (900, 600)
#: the share of pixels off by more than 24 levels between the frame in strips and the whole one. Measured:
#: 0.04-0.10 %, where the outline's lines fall a pixel apart (their ends projected through a strip's frustum round
#: otherwise; as few pixels far off, they make the RMSE 1.3-4.4 from run to run); with one strip's frustum 0.05 of
#: its half-height off (a row or two): 1.2 % off, RMSE 11.8
WHOLE_FRAME_OFF = 0.002


def last_frame(window) -> np.ndarray:
    """The render window's last frame (RGB, float64 levels), read without drawing it again."""
    return np.asarray(window.plotter.screenshot(None, return_img=True))[..., :3].astype(np.float64)


def neghip_in_strips(qtbot, make_window, monkeypatch):
    """A window of ``SIZE`` with neghip open and its final picture shown, every still frame drawn in strips
    (``SPLIT_OVER_S`` 0: the strips do not depend on this machine's speed; on it a still frame of neghip at this size
    takes 150-330 ms, over the 80 ms that start them in the app)."""
    monkeypatch.setattr(strips_module, "SPLIT_OVER_S", 0.0)
    return open_settled(qtbot, make_window, "volumes/neghip.slc", size=SIZE)


def assert_strips_left_the_whole_frame(window, monkeypatch) -> np.ndarray:
    """The frame the strips left is the same frame drawn whole (within ``WHOLE_FRAME_OFF``; no strips from then on);
    returns the whole frame."""
    striped = last_frame(window)
    monkeypatch.setattr(strips_module, "SPLIT_OVER_S", 1e9)
    window.plotter.render()
    whole = last_frame(window)
    off = float((np.abs(striped - whole).max(axis=2) > 24).mean())
    assert off < WHOLE_FRAME_OFF, (rmse(striped / 255.0, whole / 255.0), off)
    return whole
