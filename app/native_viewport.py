"""The viewport as a native X child window that VTK draws into with its own GLX context (issue #28: the default on
the ``xcb`` platform, ``VOLVIZ_VIEWPORT=qt`` keeps pyvistaqt's widget; ``viewport_types.make_plotter``).

pyvistaqt's ``QtInteractor`` is a ``QOpenGLWidget``: VTK renders into its framebuffers, the paint blits the frame into
the widget's, and Qt then composes the whole window through OpenGL (costly on a software rasteriser:
docs/bench/docstring-figures.md). VTK's own ``QVTKRenderWindowInteractor`` on a plain ``QWidget`` is a native window
that ``vtkXOpenGLRenderWindow`` swaps into directly, so Qt composes nothing for it. With the flight's frames reduced in
its own paint, a Yukon flight had far fewer long gaps and a higher frame rate (docs/bench/flight.md, "A viewport that Qt
does not compose"). A native GLX window needs X11 (pyvistaqt gh-445 left native windows for Wayland), so pyvistaqt's
widget stays the default everywhere else."""
from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING, Any

import vtkmodules.qt
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QPaintEvent, QResizeEvent, QShowEvent
from PySide6.QtWidgets import QWidget
from pyvista import global_theme
from pyvista.plotting.plotter import BasePlotter
from pyvista.plotting.render_window_interactor import RenderWindowInteractor
from pyvistaqt.plotting import _no_base_plotter_init
from vtkmodules.vtkRenderingCore import vtkRenderWindow

from volviz.render.image_overlay import window_size

vtkmodules.qt.QVTKRWIBase = "QWidget"   # read when the module below is first imported: a native QWidget, not GL
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor  # noqa: E402

if QVTKRenderWindowInteractor.__mro__[1] is not QWidget:   # imported before with another base: not native
    raise ImportError(f"vtkmodules.qt.QVTKRenderWindowInteractor is a {QVTKRenderWindowInteractor.__mro__[1]}, "
                      "not a native QWidget")

if TYPE_CHECKING:
    from .reduced_frames import ReducedFrames
    from .still_strips import StillStrips

_GL_DRAW_FRAMEBUFFER, _GL_BACK, _GL_COLOR_BUFFER_BIT, _GL_LINEAR = 0x8CA9, 0x0405, 0x4000, 0x2601
WARM_AFTER_MS = 30   # the first magnifying blit waits this long after the first paint, so that timers due run first
EXPOSE_AFTER_MS = 15  # a paint nobody asked for (an expose) is drawn this long later, one for all that came meanwhile


class _GLX:
    """The three GLX calls the reduced paint needs (``libGL.so.1``), loaded at its first use."""

    lib: Any = None

    @classmethod
    def swap_current(cls) -> None:
        if cls.lib is None:
            lib = ctypes.CDLL("libGL.so.1")
            lib.glXGetCurrentDisplay.restype = ctypes.c_void_p
            lib.glXGetCurrentDrawable.restype = ctypes.c_ulong
            lib.glXSwapBuffers.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
            cls.lib = lib
        cls.lib.glXSwapBuffers(cls.lib.glXGetCurrentDisplay(), cls.lib.glXGetCurrentDrawable())


class NativeViewport(QVTKRenderWindowInteractor, BasePlotter):
    """A pyvista plotter in VTK's native-window widget: what pyvistaqt's ``QtInteractor`` adds to its widget (the
    renderers, pyvista's interactor, key events, depth peeling, drops), with the flight's reduced frames drawn in its
    own paint (``reduce_paints``)."""

    aboutToCompose = Signal()   # never emitted: Qt composes nothing for this widget
    # pyvista's RenderWindowInteractor, as on pyvistaqt's untyped QtInteractor: the window's parts use it while the
    # window is open (BasePlotter types it Optional: None once closed)
    iren: Any

    def __init__(self, parent: QWidget | None = None) -> None:
        with _no_base_plotter_init():
            QVTKRenderWindowInteractor.__init__(self, parent)
        BasePlotter.__init__(self)
        self.setAttribute(Qt.WidgetAttribute.WA_NativeWindow)
        self.interactor = self
        self._in_paint = False
        self._asked = False          # a paint was asked for by ``update`` / ``repaint`` (else: ``_coalesce_expose``)
        self._expose_queued = False
        self._painted = 0            # paints that drew so far
        self._magnified = False   # whether a magnifying blit was drawn yet (``_magnify``)
        self._reducing = False
        self._swapped_size: tuple[int, int] | None = None   # the last frame swapped whole (``_frame_ended``)
        self.exposes_redrawn = 0     # exposes drawn from the last frame, without a render (``_exposed``)
        self._drawn_before_mapped = False
        self.frames: ReducedFrames | None = None
        self.still_strips: StillStrips | None = None   # draws slow still frames in strips (``strip_stills``)
        self.setAcceptDrops(True)   # the window's file drop filter takes them
        self.ren_win = self.GetRenderWindow()
        self.ren_win.SetMultiSamples(global_theme.multi_samples)
        for renderer in self.renderers:
            renderer.view_isometric()
            self.ren_win.AddRenderer(renderer)
        self.background_color = global_theme.background
        self._off_screen = False
        self.iren = RenderWindowInteractor(self, interactor=self.ren_win.GetInteractor())
        self.iren.interactor.RemoveObservers("MouseMoveEvent")
        self.iren.initialize()
        self.enable_trackball_style()   # type: ignore[call-arg]  # pyvista's decorator hides the bound self
        self._observers: dict[Any, Any] = {}
        self.iren.add_observer("KeyPressEvent", self.key_press_event)
        self.reset_key_events()
        if global_theme.depth_peeling["enabled"] and self.enable_depth_peeling():  # type: ignore[call-arg]
            for renderer in self.renderers:
                renderer.enable_depth_peeling()
        self._first_time = False   # BasePlotter: this plotter renders on screen
        self.ren_win.AddObserver("EndEvent", self._frame_ended)

    def reduce_paints(self, frames: ReducedFrames) -> None:
        """``frames`` decides when paints are reduced and by how much; this widget draws them so (``ReducedFrames``
        cannot resize the render window: ``vtkXOpenGLRenderWindow.SetSize`` resizes the X window)."""
        self.frames = frames

    def strip_stills(self, strips: StillStrips) -> None:
        """``strips`` draws this widget's paints at the still rate in strips when a whole frame would hold the event
        loop too long (``volviz_app.still_strips``)."""
        self.still_strips = strips

    def update(self, *args: object) -> None:
        """``QWidget.update``; the paint it asks for renders (``paintEvent``)."""
        self._asked = True
        super().update(*args)

    def repaint(self, *args: object) -> None:
        """``QWidget.repaint``; the paint renders now."""
        self._asked = True
        super().repaint(*args)

    def showEvent(self, ev: QShowEvent) -> None:
        """Shown: its first paint, in the window system's exposes of the window, is drawn later (``_coalesce_expose``),
        in a turn of the event loop of its own."""
        self._asked = False
        super().showEvent(ev)

    def draw_before_mapped(self) -> None:
        """The first time: draw a frame at the widget's size and the first magnifying blit (``_warm_magnify``) now,
        while its window is being shown, before it is mapped. A new render window's first frame at its size makes
        OpenGL's framebuffers at that size and has a software rasteriser compile shaders for them, and the first
        magnifying blit compiles its own: in the exposes' paint and the timer after it, these held the event loop of
        a window just shown over 100 ms. The exposes then draw a frame like any other."""
        if self._drawn_before_mapped or self._RenderWindow is None:
            return
        self._drawn_before_mapped = True
        self._Iren.Render()
        self._warm_magnify()

    def _coalesce_expose(self) -> None:
        """A paint nobody in Python asked for (the window system's exposes, Qt's own updates) is drawn as one asked
        for ``EXPOSE_AFTER_MS`` later: the exposes of a window being shown (two of the viewport, with the docks',
        in one turn of the event loop) were each a whole render there; now one, in a turn of its own."""
        if not self._expose_queued:
            self._expose_queued = True
            painted = self._painted
            QTimer.singleShot(EXPOSE_AFTER_MS, lambda: self._exposed(painted))

    def _exposed(self, painted: int) -> None:
        """An expose's paint: the last frame again where VTK's display framebuffer holds it (``_redraw_last``), else a
        render."""
        self._expose_queued = False
        if self._RenderWindow is None or self._painted != painted:   # (a paint asked for drew it since)
            return
        if not self._redraw_last():
            self.update()

    def _frame_ended(self, *_: object) -> None:
        """After each render: whether it was a whole frame that was swapped to the window (not a reduced frame, nor
        a strip drawn without a swap), which VTK's display framebuffer then holds at the window's size."""
        rw = self._RenderWindow
        whole = rw is not None and not self._reducing and bool(rw.GetSwapBuffers()) and bool(rw.GetDoubleBuffer())
        self._swapped_size = window_size(rw) if whole else None

    def _redraw_last(self) -> bool:
        """Draw the last frame into the window again from VTK's display framebuffer (a blit and a swap, no render),
        where it holds the window's picture: the last render swapped a whole frame at this size and no frame in
        strips is under way. An expose (a menu, a combo box's list or a dialog closed over the viewport) re-rendered
        the whole scene: a slow scene (VTK's projected tetrahedra, a CPU ray caster) held the event loop as long as
        a frame takes (issue #28). Returns whether it drew."""
        size = window_size(self._RenderWindow)
        if self._swapped_size != size or (self.still_strips is not None and self.still_strips.drawing):
            return False
        self._magnify(size, size)
        _GLX.swap_current()
        self.exposes_redrawn += 1
        return True

    def paintEvent(self, ev: QPaintEvent) -> None:
        if self._in_paint or self._RenderWindow is None:   # (closed: nothing to draw)
            return
        if not self._asked:
            self._coalesce_expose()
            return
        self._asked = False
        self._painted += 1
        frames = self.frames
        self._in_paint = True
        try:
            if frames is not None and frames.active and frames.factor > 1:
                self._reduced_render(frames)
            else:
                if self.still_strips is None or not self.still_strips.paint():
                    self._Iren.Render()
                if not self._magnified:   # the first reduced paint's one-time cost, before anything moves, after
                    self._magnified = True    # timers due (with the first paint's it held the loop 110-135 ms)
                    QTimer.singleShot(WARM_AFTER_MS, self._warm_magnify)
        finally:
            self._in_paint = False

    def _reduced_render(self, frames: ReducedFrames) -> None:
        """Render at 1/factor of the window's size into VTK's display framebuffer (no blit, no swap), magnify it into
        the window's back buffer and swap; the render window's size is the full one again afterwards."""
        rw = self._RenderWindow
        full_w, full_h = (int(v) for v in rw.GetSize())
        w, h = -(-full_w // frames.factor), -(-full_h // frames.factor)
        self._reducing = True
        try:
            vtkRenderWindow.SetSize(rw, w, h)   # the base class's: no XResizeWindow
            rw.SetFrameBlitModeToNoBlit()       # Frame() resolves into the display framebuffer ...
            rw.SetDoubleBuffer(0)               # ... and swaps only when double-buffered
            self._Iren.Render()
            frames.renders += 1
            frames.last_size = (w, h)
            self._magnify((w, h), (full_w, full_h))
            _GLX.swap_current()
        finally:
            self._reducing = False
            vtkRenderWindow.SetSize(rw, full_w, full_h)
            rw.SetFrameBlitModeToBlitToHardware()
            rw.SetDoubleBuffer(1)

    def _warm_magnify(self) -> None:
        """The first magnifying blit (``_magnify``), of 1 pixel to 2x2, which the next frame covers."""
        if self._RenderWindow is not None:
            self._magnify((1, 1), (2, 2))

    def _magnify(self, size: tuple[int, int], to: tuple[int, int]) -> None:
        """Blit the bottom-left ``size`` of VTK's display framebuffer, filtered linearly, over ``to`` of the window's
        back buffer (not swapped). A software OpenGL compiles its blit shader at the first such blit: in the first
        flight frame that made an event-loop gap over 100 ms, so the first full paint also draws one, of 1 pixel to
        2x2, which the next frame covers (docs/bench/flight.md)."""
        rw = self._RenderWindow
        rw.MakeCurrent()
        state = rw.GetState()
        state.PushDrawFramebufferBinding()
        state.vtkglBindFramebuffer(_GL_DRAW_FRAMEBUFFER, 0)
        state.vtkglDrawBuffer(_GL_BACK)
        rw.BlitDisplayFramebuffer(0, 0, 0, size[0], size[1], 0, 0, to[0], to[1], _GL_COLOR_BUFFER_BIT, _GL_LINEAR)
        state.PopDrawFramebufferBinding()
        self._magnified = True

    def render(self) -> None:  # type: ignore[override]  # BasePlotter.render, as QtInteractor's
        """``BasePlotter.render`` now (on the GUI thread), never after ``close``."""
        if getattr(self, "_closed", False):
            return
        self._rendered = True
        BasePlotter.render(self)

    def resizeEvent(self, ev: QResizeEvent) -> None:
        if self._RenderWindow is not None:
            super().resizeEvent(ev)

    def Finalize(self) -> None:
        if self._RenderWindow is not None:
            self._RenderWindow.Finalize()

    def ShowCursor(self) -> None:
        """VTK's cursor as the widget's (VTK's widget maps it a moment after VTK changes it; not once closed)."""
        if self._RenderWindow is not None:
            super().ShowCursor()

    def close(self) -> None:  # type: ignore[override]
        """As ``QtInteractor.close``: the plotter's close (it finalizes the render window while the X window still
        exists), then the widget's, then the render window is let go. Again, or from the parent's ``destroyed``:
        nothing.

        VTK opens one X connection per process to load GLX (``vtkXOpenGLRenderWindow::EnsureGLX``) and closes it
        only when its last ``vtkXOpenGLRenderWindow`` is deleted. A closed viewport's render window held until the
        process exits kept it open: an X server that stopped before (pytest-xvfb's, at the end of a test run) made
        that late ``XCloseDisplay`` Xlib's fatal I/O error, exit status 1. So the widget and its interactor drop the
        render window here (nothing else in the app holds it: ``tests/test_native_viewport_in_process.py``)."""
        if getattr(self, "_closed", True):
            return
        BasePlotter.close(self)
        QVTKRenderWindowInteractor.close(self)
        self._Iren.SetRenderWindow(None)
        self._RenderWindow = None
