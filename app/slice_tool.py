"""The slice tool: the Slices dock's edits of the scene (issue #28, "slices through a volume").

The planes are a ``slices`` component of the session (``volviz.render.slices``) on the dataset of the scene's
first regular volume, sharing that volume's transfer function, so they are saved with the session and
``volviz render`` draws them. Turning the first plane on adds the component (a document edit, rebuilt in the
background: ``volviz_app.scene_doc``); moving or toggling a plane afterwards moves the planes of the shown view at
once (``SlicesView.set_indices``, no rebuild); a plane is also dragged in the 3D view (``volviz_app.slice_drag``,
through the dock's spin box); the moves of a plane still held (dragged, or its slider down) are drawn at VTK's
interactive rate, the still frame once it is let go. Every edit is on the scene's undo stack; consecutive moves of
one plane are one step. A new transfer function recolours the planes and the 2D views.
"""
from __future__ import annotations

from typing import Any, Callable, Optional

from PySide6.QtGui import QUndoCommand

from .docks.slices import AXES, SlicesDock
from .scene_doc import edit_document, free_id
from .shown_edit import ShownEdit
from .slice_drag import SliceDrag

SLICES_ID = "slices"
_MOVE_ID = 2801     # QUndoCommand.id of plane moves (merged)


class MoveSlices(ShownEdit):
    """The slices component's planes from ``before`` to ``after`` (settings dicts), shown in place."""

    def __init__(self, tool: "SliceTool", before: dict[str, Any], after: dict[str, Any], axis: str) -> None:
        super().__init__(f"Move the {axis} slice", before, after, tool.show_settings)
        self.axis = axis

    def id(self) -> int:
        return _MOVE_ID

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, MoveSlices) or other.axis != self.axis:
            return False
        self.after = dict(other.after)
        return True


class SliceTool:
    """Connects the Slices dock to the window (module docstring)."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self.dock = SlicesDock()
        self.dock.changed.connect(self._changed)
        self._unsubscribe: Optional[Callable[[], None]] = None
        self.drag = SliceDrag(self)
        self._previewed = False     # the last move was drawn at the interactive rate: the still frame is owed
        for slider in self.dock.sliders.values():
            slider.sliderReleased.connect(self.let_go)

    # -- what is sliced -----------------------------------------------------------------------------------------------
    def volume_id(self) -> Optional[str]:
        """The component whose dataset the planes cut: the slices component, else the first regular volume."""
        from volviz.model.datasets import RegularVolume

        controller = self.window.controller
        if controller is None:
            return None
        for comp in controller.session.components:
            if comp.type == SLICES_ID:
                return str(comp.id)
        for comp in controller.session.components:
            if comp.type == "volume" and comp.visible:
                try:
                    if isinstance(controller.dataset_of(comp.id), RegularVolume):
                        return str(comp.id)
                except Exception:  # noqa: BLE001  (a component whose data cannot be shown is not sliced)
                    continue
        return None

    def slices_component(self) -> Any:
        controller = self.window.controller
        if controller is None:
            return None
        return next((c for c in controller.session.components if c.type == SLICES_ID), None)

    # -- the window's scene --------------------------------------------------------------------------------------------
    def scene_shown(self) -> None:
        """A new scene is installed: the dock shows its grid, planes and images; its TF changes recolour them."""
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        controller = self.window.controller
        comp_id = self.volume_id()
        if comp_id is None:
            self.dock.set_extent(None, "Slices need a regular volume.")
            return
        self._unsubscribe = controller.changes.subscribe(self._scene_changed)
        self.dock.set_extent(controller.dataset_of(comp_id).dimensions)
        comp = self.slices_component()
        self.dock.set_state({axis: (comp.settings.get(axis) if comp else None) for axis in AXES})
        self.show_images()

    def _scene_changed(self, change: Any) -> None:
        if change.what != "transfer_function" or self.window.controller is None:
            return
        comp = self.slices_component()
        view = self.window.controller.views.get(comp.id) if comp is not None else None
        if view is not None:
            view.set_tf(self.window.controller.transfer_function(comp.id))
        self.show_images()

    def show_images(self) -> None:
        """The 2D views of the planes that are on, in the transfer function's colours."""
        from volviz.render.slices import slice_image

        controller, comp_id = self.window.controller, self.volume_id()
        for axis in AXES:
            index = self.dock.index(axis)
            if controller is None or comp_id is None or index is None:
                self.dock.views[axis].show_rgb(None)
                continue
            tf = controller.transfer_function(comp_id)
            self.dock.views[axis].show_rgb(slice_image(controller.dataset_of(comp_id), axis, index, tf))

    def show_settings(self, settings: dict[str, Any], preview: bool = False) -> None:
        """Put ``settings`` on the slices component and move the shown planes to them (an undo or redo step; a
        ``preview``: a move of a plane still held, drawn at once at VTK's interactive rate, ``let_go`` draws the
        still frame)."""
        from volviz.render.slices import slice_indices

        comp = self.slices_component()
        if comp is None:
            return
        comp.settings = dict(settings)
        view = self.window.controller.views.get(comp.id)
        if view is not None:
            view.set_indices(slice_indices(settings))
        self.dock.set_state({axis: settings.get(axis) for axis in AXES})
        self.show_images()
        self.window.set_dirty()
        self._previewed = preview
        if preview:
            self.window.view_scheduler.render_edit(True)
        else:
            self.window.schedule_render()

    def held(self, axis: str) -> bool:
        """The user still holds the ``axis`` plane: dragged in the 3D view, or its slider pressed."""
        grabbed = self.drag.grabbed
        return (grabbed is not None and grabbed[0] == axis) or self.dock.sliders[axis].isSliderDown()

    def let_go(self) -> None:
        """A held plane is released: the still frame of where it ended (its moves were drawn at the interactive
        rate)."""
        if self._previewed:
            self._previewed = False
            self.window.schedule_render()

    # -- edits ---------------------------------------------------------------------------------------------------------
    def _changed(self, axis: str, index: Optional[int]) -> None:
        comp = self.slices_component()
        if comp is None:
            if index is not None:
                self._add(axis, index)
            return
        before = dict(comp.settings)
        after = {**before, axis: index}
        self.show_settings(after, preview=self.held(axis))
        self.window.scene_undo_stack.push(MoveSlices(self, before, after, axis))

    def _add(self, axis: str, index: int) -> None:
        volume = self.window.controller.component(self.volume_id())
        settings: dict[str, Any] = {axis: index}
        if volume.settings.get("array"):
            settings["array"] = volume.settings["array"]
        new = {"id": SLICES_ID, "type": SLICES_ID, "dataset": volume.dataset, "visible": True, "opacity": 1.0,
               "transfer_function": volume.transfer_function, "settings": settings}

        def change(doc: dict[str, Any]) -> None:
            doc["components"].append({**new, "id": free_id(doc, SLICES_ID)})

        self.show_images()
        edit_document(self.window, self.window.scene_undo_stack, change, f"Show the {axis} slice")
