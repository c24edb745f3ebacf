"""One render per mouse move while the user drags the camera.

pyvistaqt's viewport renders twice for each move of a drag: VTK's interactor style renders when it moves the camera, and
the repaint that this render schedules renders again (pyvistaqt's ``paintGL`` always renders, since PyVista changes
scenes without asking for a repaint). On a software OpenGL each render of a large viewport is costly
(docs/bench/docstring-figures.md), so a drag spent half its time drawing frames nobody saw. While an interaction lasts,
the interactor's own renders are turned into repaint requests; the repaint draws the frame once. Outside interactions
nothing changes.

An interaction's end (a drag released, a wheel notch) is drawn the same way: VTK's style renders a whole still frame
in its handler right after the interaction's end (``vtkInteractorStyle::StopState``), which held the event loop for
the still frame of a volume on every wheel notch and release, and the repaint drew it again. Its end is a repaint at
the interactive rate; the still frame follows once no interaction has begun for ``SETTLE_MS``, as a repaint (which
draws a slow still frame in strips, ``volviz_app.still_strips``; issue #28: no event-loop stall over 100 ms).

The app re-makes its CPU volume images while the camera moves and after, so its plotter's CPU PT volumes draw those
frames with the camera of the image they show (``volviz.render.preview_hold``, issue #28)."""
from __future__ import annotations

from typing import Any

from PySide6.QtCore import QTimer

from volviz.render.preview_hold import hold_previews

SETTLE_MS = 150   # the still frame is drawn once no interaction has begun for this long after the last one ended


class SingleRenderDuringInteraction:
    def __init__(self, plotter: Any) -> None:
        self.widget = plotter.interactor
        self.iren = plotter.iren.interactor          # the vtkRenderWindowInteractor
        hold_previews(plotter)
        self.interacting = False
        self.settle = QTimer(self.widget)            # (the widget's: it stops with it)
        self.settle.setSingleShot(True)
        self.settle.setInterval(SETTLE_MS)
        self.settle.timeout.connect(self._settled)
        self.iren.AddObserver("StartInteractionEvent", self._start)
        self.iren.AddObserver("EndInteractionEvent", self._end)
        self.iren.AddObserver("RenderEvent", self._render_requested)

    def _start(self, *args: Any) -> None:
        self.interacting = True
        self.settle.stop()
        self.iren.EnableRenderOff()

    def _end(self, *args: Any) -> None:
        # the style has set the still rate and renders right after this event: a repaint request, while rendering
        # stays off until the next turn of the event loop; the repaint at the interactive rate
        self.interacting = False
        self.iren.GetRenderWindow().SetDesiredUpdateRate(self.iren.GetDesiredUpdateRate())
        self.widget.update()
        QTimer.singleShot(0, self._enable)
        self.settle.start()

    def _enable(self) -> None:
        if not self.interacting:
            self.iren.EnableRenderOn()

    def _settled(self) -> None:
        if not self.interacting and self.iren.GetRenderWindow() is not None:
            self.iren.GetRenderWindow().SetDesiredUpdateRate(self.iren.GetStillUpdateRate())
            self.widget.update()                    # the still frame

    def _render_requested(self, *args: Any) -> None:
        if self.iren.GetEnableRender():
            return                                  # rendered already (outside an interaction)
        if getattr(self.widget, "_in_paint", False):
            self.iren.GetRenderWindow().Render()    # the repaint: the one render of this frame
        else:
            self.widget.update()                    # a move: ask for a repaint instead of rendering now
