"""Slices dragged in the 3D view: a left press on a shown plane grabs it (the camera does not move), moving the mouse
moves the plane along its axis to the grid index nearest the mouse ray (``volviz.render.slices.drag_index``), and
the release lets go (a closed hand meanwhile; the moves are drawn at VTK's interactive rate, the release draws the
still frame: ``SliceTool.let_go``). The plane moves through the Slices dock's spin box, so the slider,
the 2D view, the scene and the undo stack (consecutive moves of one plane: one step) follow as for a slider move
(``volviz_app.slice_tool``)."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import QEvent, QObject, Qt


class SliceDrag(QObject):
    """The event filter on ``tool.window.plotter.interactor`` (module docstring); ``grabbed`` is the dragged
    plane's (axis, the world point grabbed) or None."""

    def __init__(self, tool: Any) -> None:
        super().__init__(tool.window)
        self.tool = tool
        self.grabbed: Optional[tuple[str, Any]] = None
        tool.window.plotter.interactor.installEventFilter(self)

    def _display(self, watched: Any, event: Any) -> tuple[float, float]:
        """The event's position in VTK's display coordinates (device pixels, rows up from the bottom)."""
        pos, ratio = event.position(), watched.devicePixelRatioF()
        return pos.x() * ratio, self.tool.window.plotter.ren_win.GetSize()[1] - 1 - pos.y() * ratio

    def _view(self) -> Any:
        comp, controller = self.tool.slices_component(), self.tool.window.controller
        return None if comp is None or controller is None else controller.views.get(comp.id)

    def eventFilter(self, watched: Any, event: Any) -> bool:  # noqa: N802 (Qt's name)
        kind = event.type()
        if kind == QEvent.Type.MouseButtonPress and event.button() == Qt.MouseButton.LeftButton \
                and event.modifiers() == Qt.KeyboardModifier.NoModifier:
            view = self._view()
            self.grabbed = None if view is None else view.plane_at(self.tool.window.plotter.renderer,
                                                                   *self._display(watched, event))
            if self.grabbed is not None:
                watched.setCursor(Qt.CursorShape.ClosedHandCursor)
            return self.grabbed is not None
        if self.grabbed is None:
            return False
        if kind == QEvent.Type.MouseMove:
            self._move(*self._display(watched, event))
            return True
        if kind == QEvent.Type.MouseButtonRelease and event.button() == Qt.MouseButton.LeftButton:
            self.grabbed = None
            watched.unsetCursor()
            self.tool.let_go()
            return True
        return False

    def _move(self, x: float, y: float) -> None:
        from volviz.render.probe_pick import pick_ray
        from volviz.render.slices import drag_index

        axis, anchor = self.grabbed  # type: ignore[misc]
        controller = self.tool.window.controller
        origin, direction = pick_ray(controller.plotter.renderer, x, y)
        index = drag_index(controller.dataset_of(self.tool.volume_id()), axis, anchor, origin, direction)
        spin = self.tool.dock.spins[axis]
        if spin.value() != index:
            spin.setValue(index)        # the dock's own path: slider, 2D view, scene, undo
