"""The viewport's frames at a reduced resolution while flying (issue #28: the natural scene while flying shows
reduced-resolution frames and never blocks the window).

On a software OpenGL (Mesa llvmpipe) VTK's render of a frame runs on the GUI thread in the widget's paint, and much
of it scales with the pixels drawn: the sky dome, the terrain's shaded fragments, the fog overlay's blend. While
``active``, each render of a paint draws into VTK's framebuffers at 1/``factor`` of the viewport's size in each
direction (set on the render window at the render's ``StartEvent``), and the widget's blit of VTK's frame into its own
framebuffer (pyvistaqt's ``paintGL``: ``BlitDisplayFramebuffer`` with linear filtering, from the render window's
size to the widget's) magnifies it to the viewport. As soon as Qt composes the window after the paint
(``aboutToCompose``), or at the latest when the event loop runs next (a zero timer, where nothing composes), the
render window has the viewport's size again: whatever reads it between paints (the camera
views' requests, read-backs, screenshots, a render outside a paint) sees the full size, and a render outside a paint
is never reduced.

``start()`` at each step of a flight; ``ending()`` gives the callback that ends the reduced frames (and asks for the
full-resolution frame) unless a newer flight started since: the app calls it once the views' full-size updates that
follow the flight's stop are shown, so no frame between the stop and them is drawn at full size."""
from __future__ import annotations

from typing import Any, Callable

from PySide6.QtCore import QTimer

FACTOR = 2   # a quarter of the pixels: a Yukon flight frame's render, median 21-45 -> 9-17 ms (docs/bench/flight.md)


class ReducedFrames:
    """The reduced paints of a ``pyvistaqt.QtInteractor`` plotter (see the module's docstring). Starts inactive."""

    def __init__(self, plotter: Any, factor: int = FACTOR) -> None:
        self.widget = plotter.interactor
        self.factor = max(1, int(factor))
        self.active = False
        self.renders = 0             # paints drawn reduced so far
        self.last_size: tuple[int, int] = (0, 0)   # the render window's size in the last reduced paint
        self._full: tuple[int, int] | None = None   # the render window's size before it was reduced
        self._serial = 0
        reduce_paints = getattr(self.widget, "reduce_paints", None)
        if reduce_paints is not None:   # a native viewport (app/native_viewport.py) draws its paints reduced itself
            reduce_paints(self)   # (and holds no render window: a closed one's X connection stays open while held)
            return
        self.ren_win = plotter.ren_win
        self.ren_win.AddObserver("StartEvent", self._render_starts)
        self.widget.aboutToCompose.connect(self._restore)

    def start(self) -> None:
        """A flight step: the paints from now on are reduced (a pending ``ending`` callback no longer ends them)."""
        self.active = self.factor > 1
        self._serial += 1

    def stop(self) -> None:
        """Full-resolution frames again, and one asked for now."""
        self._serial += 1
        if self.active:
            self.active = False
            self.widget.update()

    def ending(self) -> Callable[[], None]:
        """A callback that ends the reduced frames (``stop``) unless ``start`` was called after this call."""
        serial = self._serial

        def end() -> None:
            if self._serial == serial:
                self.stop()

        return end

    def _render_starts(self, *args: Any) -> None:
        """A render begins: reduced in a paint while active (from the render window's size, which a resize of the
        viewport in the meantime has changed), else at the size it had before."""
        if not (self.active and getattr(self.widget, "_in_paint", False)):   # pyvistaqt's paintGL renders
            self._restore()
            return
        size = tuple(int(v) for v in self.ren_win.GetSize())
        if self._full is None or size != self.last_size:
            self._full = (size[0], size[1])
        w, h = self._full
        self.last_size = (-(-w // self.factor), -(-h // self.factor))
        self.renders += 1
        if size != self.last_size:
            self.ren_win.SetSize(*self.last_size)
            QTimer.singleShot(0, self._restore)     # after the paint's blit, whether or not the window composes

    def _restore(self) -> None:
        """The render window back at its size (the paint's blit has used the reduced frame)."""
        full, self._full = self._full, None
        if full is not None and tuple(self.ren_win.GetSize()) == self.last_size:
            self.ren_win.SetSize(*full)
