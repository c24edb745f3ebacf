"""Still frames drawn in strips across turns of the event loop (issue #28: no event-loop stall over 100 ms in any
flow).

VTK renders on the GUI thread; on a software OpenGL a still frame of a regular volume holds it well over 100 ms at
the window's size (measured in docs/bench/flow-gaps.md). When the last still frame took longer than
``strips.SPLIT_OVER_S`` and VTK draws the scene under at most images of ours (``SceneController.drawn_in_strips``),
a paint of the native viewport at the still rate draws the frame in strips (``volviz.render.strips``: ``strips_for``
of them), one per turn of the event loop; the window shows the previous frame until the last strip swaps. A render
by anyone else in between (``plotter.render()``: it draws a whole frame) or a paint at the interactive rate ends the
strips; a newer paint starts them over. The window's ``render_scene`` asks for such a paint instead of rendering
when ``wanted()``; other renders outside a paint (screenshots, exports, read-backs) draw whole frames.
"""
from __future__ import annotations

import time
from typing import Any, Callable, Optional

from PySide6.QtCore import QTimer

from volviz.render import strips
from volviz.render.image_overlay import Buffers, image_renderers, read_buffers
from volviz.render.strips import StripFrame, can_strip, strips_for


FRAME_STARTS_MS = 100   # a read-back waits this long for the paint it asked for to start a frame in strips


class StillStrips:
    """Paints of a native viewport's still frames in strips (see the module's docstring); ``allowed()`` says
    whether the scene shown can be drawn so; ``drawn(seconds)`` is told each frame drawn in strips and what its passes
    took together."""

    def __init__(self, plotter: Any, allowed: Callable[[], bool],
                 drawn: Optional[Callable[[float], None]] = None) -> None:
        self.plotter, self.allowed, self.drawn = plotter, allowed, drawn
        self.frame: Optional[StripFrame] = None
        self.cost = 0.0        # seconds the last still frame took to draw (whole, or its passes together)
        self.frames = 0        # frames drawn in strips so far
        self.longest = 0.0     # the longest pass of the last frame drawn in strips (seconds)
        self.last_rows: list[tuple[int, int]] = []   # the rows [lo, hi) of its strips
        self.profile: list[tuple[int, int, float]] = []   # its strips' rows and seconds: the next frame's plan
        self.pays = True       # whether strips pay in this scene (its thinnest strip took under ``PAYS_UNDER_S``)
        self._renders = 0      # renders of the window so far: one by anyone else ends a frame's strips
        self._mark = 0
        self._ours = False
        self._started = 0.0
        self._spent: list[float] = []
        self._waiters: list[Callable[[Optional[Buffers]], None]] = []   # ``after_still_frame``'s
        self._drawn: Optional[Buffers] = None      # the opaque scene read back from the frame being drawn
        self._last_share: Optional[float] = None   # the last strip's share of the frame just drawn in strips
        self._allotted: Optional[float] = None     # the renderer's allotted time while a render has it scaled
        # (the render window is not held here: its observers hold this object, and a closed viewport's window held
        # keeps VTK's X connection open, tests/test_native_viewport_in_process.py)
        plotter.ren_win.AddObserver("StartEvent", self._render_starts)
        plotter.ren_win.AddObserver("EndEvent", self._render_ends)

    @property
    def drawing(self) -> bool:
        """Whether a frame is being drawn in strips (its last strip not swapped yet)."""
        return self.frame is not None

    def _still(self) -> bool:
        ren_win, iren = self.plotter.ren_win, self.plotter.iren
        if ren_win is None or iren is None:   # closed
            return False
        iren = iren.interactor if hasattr(iren, "interactor") else iren
        return bool(ren_win.GetDesiredUpdateRate() <= iren.GetStillUpdateRate())

    def _render_starts(self, *args: Any) -> None:
        self._renders += 1
        self._started = time.perf_counter()
        share, self._last_share = self._last_share, None
        if share is None and not self._ours and self.frame is not None and self.frame.costs:
            share = strips.last_strip_share(self.frame.costs, self.frame.height)   # a frame this render cuts short
        if not self._ours and share is not None and not self._still():
            # the first render at the interactive rate after a frame in strips (``strips.last_strip_share``)
            renderer = self.plotter.renderer
            self._allotted = renderer.GetAllocatedRenderTime()
            renderer.SetAllocatedRenderTime(self._allotted * share)

    def _render_ends(self, *args: Any) -> None:
        if self._allotted is not None:
            self.plotter.renderer.SetAllocatedRenderTime(self._allotted)
            self._allotted = None
        if not self._ours and self._still():
            self.cost = time.perf_counter() - self._started

    def after_still_frame(self, done: Callable[[Optional[Buffers]], None]) -> bool:
        """Draw a still frame in strips from the next paint (or finish the one being drawn) and hand ``done`` the
        opaque scene read back from it in the turn of its last pass: (z, rgb) at the window's size, read once its
        strips drew the scene, before their last pass drew the 2D props and the images over it
        (``StripFrame.after_base``; what ``OverlayView.begin`` reads back, there from a whole frame of its own, a
        long stall under the isosurfaces' CPU overlay). ``done(None)`` when the frame is not finished
        (a render by anyone else, a move, another scene). False, ``done`` not kept: still frames are not drawn in
        strips now."""
        if not self.wanted():
            return False
        self._waiters.append(done)
        if self.frame is None:
            self.plotter.interactor.update()
            QTimer.singleShot(FRAME_STARTS_MS, self._unless_drawing)
        elif self.frame.after_base is None:   # a frame being drawn: read back once its strips drew the scene
            self.frame.read_after_base(self._read_back, image_renderers(self.plotter))
        return True

    def _unless_drawing(self) -> None:
        """The paint asked for drew no frame in strips (a reduced flight frame, or none yet): the waiters read back
        themselves."""
        if self.frame is None and self._waiters:
            self._serve(None)

    def _read_back(self) -> None:
        ren_win = self.plotter.ren_win
        w, h = (int(v) for v in ren_win.GetSize())
        self._drawn = read_buffers(ren_win, w, h)

    def _serve(self, drawn: Optional[Buffers]) -> None:
        waiters, self._waiters, self._drawn = self._waiters, [], None
        for done in waiters:
            done(drawn)

    def new_scene(self) -> None:
        """A new scene is shown: its first still frame's cost is not known, and on a software OpenGL its first frame
        also builds the mappers' textures and tables; it is drawn in strips as though it took
        ``strips.FIRST_FRAME_S`` (where VTK draws it alone), then by its own cost."""
        self.cost = strips.FIRST_FRAME_S
        self.profile = []
        self.pays = True
        self._serve(None)

    def wanted(self) -> bool:
        """Whether the next still frame is drawn in strips: the last took longer than ``strips.SPLIT_OVER_S``, the
        window is at its still rate, the scene allows it, and strips paid in it so far."""
        return (self.cost > strips.SPLIT_OVER_S and self.pays and self._still() and self.allowed()
                and can_strip(self.plotter.ren_win, self.plotter.renderer))

    def paint(self) -> bool:
        """A paint of the viewport: its frame's first strip drawn now and the others queued (True), or nothing
        drawn (False: the caller renders the whole frame)."""
        self.frame = None
        if not self.wanted():
            self._serve(None)
            return False
        self._drawn = None
        self.frame = StripFrame(self.plotter.ren_win, self.plotter.renderer, strips_for(self.cost),
                                strips.PASS_BUDGET_S, self.profile,
                                after_base=self._read_back if self._waiters else None,
                                images=image_renderers(self.plotter), stop_after_s=strips.STOP_AFTER_S)
        self._spent = []
        self._step(self.frame)
        return True

    def _step(self, frame: StripFrame) -> None:
        self._ours = True
        start = time.perf_counter()
        try:
            frame.step()
        finally:
            self._ours = False
        self._spent.append(time.perf_counter() - start)
        self._mark = self._renders
        if frame.done:
            self.frame = None
            self.frames += 1
            self.cost, self.longest, self.last_rows = sum(self._spent), max(self._spent), list(frame.drawn)
            self.profile = list(frame.costs)
            self._last_share = strips.last_strip_share(frame.costs)
            # a scene whose every strip costs as much as a pass may (geometry: each pass draws all of it) is drawn
            # whole until the next scene: one stall instead of one per strip
            self.pays = min((seconds for _, _, seconds in frame.costs), default=0.0) < strips.PAYS_UNDER_S
            if self.drawn is not None:
                self.drawn(self.cost)
            self._serve(self._drawn)
        else:
            QTimer.singleShot(0, lambda: self._next(frame))

    def _next(self, frame: StripFrame) -> None:
        if frame is not self.frame:                 # a newer paint started its own
            return
        if self._renders != self._mark or not self._still():     # (not still: also once the viewport is closed)
            if self._renders == self._mark and frame.costs:   # cut short by a move or a playback: its first render
                self._last_share = strips.last_strip_share(frame.costs, frame.height)   # comes after a strip
            self.frame = None                       # a whole frame was drawn since, or the camera moves
            self._serve(None)
            return
        if frame.stale():                           # the camera or the window changed between two strips
            self.frame = None
            self.plotter.interactor.update()        # the frame again, from its first strip
            return
        self._step(frame)
