"""Drag the selected clipping plane in the viewport: a VTK implicit-plane widget (through PyVista) bound to the clipping
dock. Releasing the widget edits the plane through the dock (one undo step, the same path as the spin boxes); dock
edits and selection move the widget."""
from __future__ import annotations

from typing import Any, Optional

from volviz_app.docks.clipping import ClippingDock, plane_offset


class ClipPlaneWidget:
    def __init__(self, plotter: Any, dock: ClippingDock):
        self.plotter = plotter
        self.dock = dock
        self.widget: Optional[Any] = None
        self._row = -1
        dock.show_widget.toggled.connect(self.refresh)
        dock.refreshed.connect(self.refresh)

    def refresh(self, *args: Any) -> None:
        """Show the widget on the selected plane when the dock asks for it, else remove it."""
        row = self.dock.plane_list.currentRow()
        planes = self.dock.clip["planes"]
        wanted = self.dock.show_widget.isChecked() and 0 <= row < len(planes)
        if not wanted:
            self._remove()
            return
        normal, _ = plane_offset(planes[row])
        origin = planes[row]["point"]
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
        if 0 <= self._row < len(self.dock.clip["planes"]):
            n = [float(v) for v in normal]
            self.dock.set_plane(self._row, n, sum(float(o) * v for o, v in zip(origin, n)))

    def _remove(self) -> None:
        if self.widget is not None:
            self.widget.Off()
            widgets = self.plotter.widgets.plane_widgets
            if self.widget in widgets:
                widgets.remove(self.widget)
            self.widget = None
            self.plotter.render()
