"""Draw a moving camera's frames with the camera of the CPU volume image on screen (issue #28).

A CPU PT image (``volviz.render.pt_prop.PTVolume``) is made on a worker for the camera of its ``begin``; while the
mouse drags the camera, VTK draws its own props (the outline box, opaque geometry) at every frame for the newest
camera, so the volume preview was drawn for a camera several frames older than the box around it: the two slid
apart and the opaque depth the image was cut by no longer lay under the box. From the start of an interaction until
a full-size image of the live camera is shown after its end, each render of the plotter's renderer is drawn with
the camera the shown image was made for (swapped in at the renderer's ``StartEvent``, the live camera put back at
its ``EndEvent``): box and volume agree, and the whole view lags the mouse by the image's age instead. The swap
runs before the orientation axes copy the camera into their own renderer, so they are drawn at the same camera.
``frames`` logs per frame (live camera serial, image camera serial, drawn camera serial) for the flow test and the
statement of the lag.

Only for a plotter whose owner re-makes the images while the camera moves and after (the app:
``hold_previews(plotter)``); elsewhere an interactive plotter would stay at the image's camera after a drag.
"""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:   # type-only: VTK's camera, reached through the facade at run time; PyVista's plotter
    import pyvista as pv

    from volviz.render.vtk_facade import vtkCamera

__all__ = ["PreviewCameraHold", "hold_previews", "holds_previews"]

AXES_FIRST = 10.0     # the swap's StartEvent priority: before vtkOrientationMarkerWidget's camera update runs
_holding: weakref.WeakSet[Any] = weakref.WeakSet()   # the plotters whose CPU volumes hold their images' camera


def hold_previews(plotter: pv.BasePlotter) -> None:
    """The CPU PT volumes of ``plotter`` made from now on draw moving frames with their image's camera."""
    _holding.add(plotter)


def holds_previews(plotter: pv.BasePlotter) -> bool:
    return plotter in _holding


def _key(camera: Any) -> tuple[Any, ...]:
    return (camera.GetPosition(), camera.GetFocalPoint(), camera.GetViewUp(), camera.GetViewAngle(),
            camera.GetParallelProjection(), camera.GetParallelScale())


def _assign(camera: vtkCamera, source: vtkCamera) -> None:
    """``camera`` set to ``source``'s parameters, and marked modified: ``DeepCopy`` keeps the time stamp, and VTK's
    OpenGL camera re-uses its matrices until the camera's time stamp passes theirs, so a frame drew with the matrices
    of the camera swapped in or out before (issue #28: after an orbit the outline box, and the opaque depth the next
    volume image was cut by, stayed at a preview's camera while the image was made for the live one)."""
    camera.DeepCopy(source)
    camera.Modified()


class PreviewCameraHold:
    """The camera swap of the module docstring for one plotter; ``snapshot`` in a view's ``begin``, ``shown`` in
    its ``finish``, ``suspend`` around the opaque render of ``begin`` (which must see the live camera)."""

    FRAME_LOG = 1000

    def __init__(self, plotter: Any) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        self._vtk = vtk
        self.renderer = plotter.renderer
        self.image_camera: Any = None      # a copy of the camera the shown image was made for
        self.image_serial = 0
        self.interacting = False
        self.holding = False               # from an interaction's start until an image of the live camera is shown
        self.suspended = False
        self.live_serial = 0               # a new serial whenever a frame's live camera differs from the last one's
        self.frames: list[tuple[int, int, int]] = []
        self._last_key: Any = None
        self._live = vtk.vtkCamera()
        self._swapped = False
        iren = plotter.iren.interactor
        self._observers = [
            # before the orientation axes' observer copies the camera into their renderer, so they are
            # drawn at the camera the scene is (issue #28: they followed the live camera, ~10 frames apart)
            (self.renderer, self.renderer.AddObserver("StartEvent", self._start, AXES_FIRST)),
            (self.renderer, self.renderer.AddObserver("EndEvent", self._end)),
            (iren, iren.AddObserver("StartInteractionEvent", self._interaction_started)),
            (iren, iren.AddObserver("EndInteractionEvent", lambda *a: setattr(self, "interacting", False))),
        ]

    def _interaction_started(self, *_: Any) -> None:
        self.interacting = self.holding = True

    def snapshot(self) -> tuple[vtkCamera, int]:
        """The live camera now (a copy) and its serial, for the image a ``begin`` starts."""
        live = self.renderer.GetActiveCamera()
        copy = self._vtk.vtkCamera()
        copy.DeepCopy(live)
        return copy, self.live_serial + (_key(live) != self._last_key)

    def shown(self, snapshot: tuple[vtkCamera, int], preview: bool) -> None:
        """A ``finish`` showed an image made for ``snapshot``'s camera."""
        self.image_camera, self.image_serial = snapshot
        if self.holding and not self.interacting and not preview \
                and _key(self.image_camera) == _key(self.renderer.GetActiveCamera()):
            self.holding = False

    def _start(self, *_: Any) -> None:
        if self.suspended:
            return
        live = self.renderer.GetActiveCamera()
        key = _key(live)
        if key != self._last_key:
            self.live_serial += 1
            self._last_key = key
        drawn = self.live_serial
        if self.holding and self.image_camera is not None and _key(self.image_camera) != key:
            self._live.DeepCopy(live)
            _assign(live, self.image_camera)
            self._swapped = True
            drawn = self.image_serial
        self.frames.append((self.live_serial, self.image_serial, drawn))
        del self.frames[:-self.FRAME_LOG]

    def _end(self, *_: Any) -> None:
        if self._swapped:
            _assign(self.renderer.GetActiveCamera(), self._live)
            self._swapped = False

    def remove(self) -> None:
        self._end()
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers = []
