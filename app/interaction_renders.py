"""One render per mouse move while the user drags the camera.

pyvistaqt's viewport renders twice for each move of a drag: VTK's interactor style renders when it moves the camera, and
the repaint that this render schedules renders again (pyvistaqt's ``paintGL`` always renders, since PyVista changes
scenes without asking for a repaint). On a software OpenGL each render of a large viewport is costly
(docs/bench/docstring-figures.md), so a drag spent half its time drawing frames nobody saw. While an interaction lasts,
the interactor's own renders are turned into repaint requests; the repaint draws the frame once. Outside interactions
nothing changes.

The app re-makes its CPU volume images while the camera moves and after, so its plotter's CPU PT volumes draw those
frames with the camera of the image they show (``volviz.render.preview_hold``, issue #28)."""
from __future__ import annotations

from typing import Any

from volviz.render.preview_hold import hold_previews


class SingleRenderDuringInteraction:
    def __init__(self, plotter: Any) -> None:
        self.widget = plotter.interactor
        self.iren = plotter.iren.interactor          # the vtkRenderWindowInteractor
        hold_previews(plotter)
        self.iren.AddObserver("StartInteractionEvent", self._start)
        self.iren.AddObserver("EndInteractionEvent", self._end)
        self.iren.AddObserver("RenderEvent", self._render_requested)

    def _start(self, *args: Any) -> None:
        self.iren.EnableRenderOff()

    def _end(self, *args: Any) -> None:
        self.iren.EnableRenderOn()
        self.widget.update()                        # the final frame of the interaction

    def _render_requested(self, *args: Any) -> None:
        if self.iren.GetEnableRender():
            return                                  # rendered already (outside an interaction)
        if getattr(self.widget, "_in_paint", False):
            self.iren.GetRenderWindow().Render()    # the repaint: the one render of this frame
        else:
            self.widget.update()                    # a move: ask for a repaint instead of rendering now
