"""Drag the selected clipping plane and the crop box in the viewport: a VTK implicit-plane widget and a box widget
(through PyVista) bound to the clipping dock. Releasing a widget edits the plane or box through the dock (one undo
step, the same path as the spin boxes); dock edits and selection move the widgets."""
from __future__ import annotations

from typing import Any, Optional

from .docks.clipping import ClippingDock, plane_offset


class ClipPlaneWidget:
    def __init__(self, plotter: Any, dock: ClippingDock):
        self.plotter = plotter
        self.dock = dock
        self.widget: Optional[Any] = None
        self.box_widget: Optional[Any] = None
        self._row = -1
        self._placing = False
        dock.show_widget.toggled.connect(self.refresh)
        dock.refreshed.connect(self.refresh)

    def refresh(self, *args: Any) -> None:
        self._refresh_box()
        self._refresh_plane()

    def _refresh_box(self) -> None:
        """The box widget on the crop box while box crop is on and widgets are shown."""
        box = self.dock.clip.box
        if not (self.dock.show_widget.isChecked() and box is not None):
            _drop(self.box_widget, self.plotter.widgets.box_widgets)
            self.box_widget = None
            return
        bounds = [v for pair in zip(box.lo, box.hi) for v in pair]
        self._placing = True
        try:
            if self.box_widget is None:
                self.box_widget = self.plotter.add_box_widget(self._box_moved, bounds=bounds, factor=1.0,
                                                              rotation_enabled=False, interaction_event="end")
            else:
                self.box_widget.PlaceWidget(bounds)
        finally:
            self._placing = False

    def _box_moved(self, box: Any) -> None:
        if self._placing or self.dock.clip.box is None:
            return
        b = box.bounds
        self.dock.set_box(b[0::2], b[1::2])

    def _refresh_plane(self) -> None:
        """Show the widget on the selected plane when the dock asks for it, else remove it."""
        row = self.dock.plane_list.currentRow()
        planes = self.dock.clip.planes
        wanted = self.dock.show_widget.isChecked() and 0 <= row < len(planes)
        if not wanted:
            self._remove()
            return
        normal, _ = plane_offset(planes[row])
        origin = planes[row].point
        if self.widget is None:
            self.widget = self.plotter.add_plane_widget(self._moved, normal=normal, origin=origin,
                                                        bounds=self.dock.bounds, test_callback=False,
                                                        interaction_event="end")
        else:
            self.widget.SetNormal(*normal)
            self.widget.SetOrigin(*origin)
        self._row = row
        self.plotter.render()

    def _moved(self, normal: Any, origin: Any) -> None:
        if 0 <= self._row < len(self.dock.clip.planes):
            n = [float(v) for v in normal]
            self.dock.set_plane(self._row, n, sum(float(o) * v for o, v in zip(origin, n)))

    def _remove(self) -> None:
        if self.widget is not None:
            _drop(self.widget, self.plotter.widgets.plane_widgets)
            self.widget = None
            self.plotter.render()


def _drop(widget: Any, registry: list[Any]) -> None:
    """Switch a widget off and forget it (PyVista keeps a list of its widgets)."""
    if widget is not None:
        widget.Off()
        if widget in registry:
            registry.remove(widget)
