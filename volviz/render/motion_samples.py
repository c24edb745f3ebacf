"""Multisampling off while the camera moves, on a software OpenGL.

A PyVista window draws with 4x multisampling. On a software rasteriser (llvmpipe) that is four times the fill plus a
resolve per frame: the Yukon scene at 990x673 took 3-4x as long with it (docs/bench/nature.md, "frames while
moving"), which made each frame drawn while flying or orbiting block the window. While the camera moves, frames are
previews anyway (reduced-size overlays, a coarse terrain); the still frame after the motion is drawn with the
window's multisampling again, so the picture the user is left with is unchanged. On a hardware driver nothing
changes (multisampling is nearly free there)."""
from __future__ import annotations

from typing import Any

from volviz.render.backend import plotter_gl_info
from volviz.render.image_overlay import hold_single_sample, release_single_sample


class SingleSampleWhileMoving:
    """``moving()`` when a camera motion starts or goes on, ``stopped()`` when it is over (see the module doc).
    ``software``: whether the plotter's OpenGL is a software one (None: ask the driver)."""

    def __init__(self, plotter: Any, software: bool | None = None) -> None:
        self.plotter = plotter
        self._software = software
        self.held = False

    @property
    def enabled(self) -> bool:
        if self._software is None:
            self._software = bool(plotter_gl_info(self.plotter).software)
        return self._software

    def moving(self) -> None:
        if not self.held and self.plotter.ren_win is not None and self.enabled:
            hold_single_sample(self.plotter, self)
            self.held = True

    def stopped(self) -> None:
        if self.held and self.plotter.ren_win is not None:
            release_single_sample(self.plotter, self)
        self.held = False
