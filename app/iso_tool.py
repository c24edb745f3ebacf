"""The iso tool: the Isosurfaces dock's edits of the scene (issue #28, "isosurfaces from the GUI").

The surfaces are the ``styles`` of the scene's isosurface component (``volviz.iso.component``); without one, adding
the first surface adds an ``isosurface`` component on the dataset (and array) of the scene's first volume; removing
the last one removes the component. The transparency mode is the render option ``iso_mode``. Every edit is a
document edit (``volviz_app.scene_doc``: rebuilt in the background, same camera) on the scene's undo stack. A new
surface without a chosen colour takes the transfer function's colour at its value (``slices.value_color``).
"""
from __future__ import annotations

from typing import Any, Optional

from .docks.isosurfaces import IsosurfacesDock
from .scene_doc import edit_document, free_id

ISO_ID = "isosurfaces"


class IsoTool:
    """Connects the Isosurfaces dock to the window (module docstring)."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self.dock = IsosurfacesDock()
        self.dock.added.connect(self.add)
        self.dock.edited.connect(self.edit)
        self.dock.removed.connect(self.remove)
        self.dock.modeChosen.connect(self.set_mode)

    def iso_component(self) -> Any:
        controller = self.window.controller
        if controller is None:
            return None
        return next((c for c in controller.session.components if c.type == "isosurface"), None)

    def volume_component(self) -> Any:
        controller = self.window.controller
        if controller is None:
            return None
        return next((c for c in controller.session.components if c.type in ("volume", "mesh", "demo")
                     and c.dataset is not None), None)

    def scene_shown(self) -> None:
        """A new scene is installed: the dock lists its surfaces and mode."""
        iso, volume = self.iso_component(), self.volume_component()
        if iso is None and volume is None:
            self.dock.load([], "vtk", None)
            self.dock.set_enabled(False, "Isosurfaces need a volume.")
            return
        self.dock.set_enabled(True)
        styles = (iso.settings.get("styles") or []) if iso is not None else []
        tf = self.window.controller.transfer_function(volume.id) if volume is not None else None
        self.dock.load([self._full(s) for s in styles], self.window.session.render.options.get("iso_mode", "vtk"),
                       tf.range if tf is not None else None)

    @staticmethod
    def _full(style: dict[str, Any]) -> dict[str, Any]:
        """A style with its defaults (``IsoStyleSettings``)."""
        from volviz.model.settings import IsoStyleSettings

        return IsoStyleSettings.model_validate(style).model_dump()

    def _style(self, style: dict[str, Any]) -> dict[str, Any]:
        """The dock's style with a colour: the transfer function's at the value when none was chosen."""
        from volviz.render.slices import value_color

        out = dict(style)
        volume = self.volume_component()
        if out.get("color") is None:
            tf = self.window.controller.transfer_function(volume.id) if volume is not None else None
            out["color"] = list(value_color(tf, out["value"])) if tf is not None else [1.0, 1.0, 1.0]
        out["color"] = [float(c) for c in out["color"]]
        return out

    def _edit(self, change: Any, text: str) -> bool:
        return edit_document(self.window, self.window.scene_undo_stack, change, text)

    @staticmethod
    def _find(doc: dict[str, Any]) -> Optional[dict[str, Any]]:
        return next((c for c in doc["components"] if c["type"] == "isosurface"), None)

    def add(self, style: dict[str, Any]) -> bool:
        """Add a surface (and the isosurface component when there is none)."""
        if self.window.controller is None:
            return False
        new = self._style(style)
        volume = self.volume_component()

        def change(doc: dict[str, Any]) -> None:
            comp = self._find(doc)
            if comp is None:
                settings: dict[str, Any] = {"styles": []}
                if volume.settings.get("array"):
                    settings["scalars"] = volume.settings["array"]
                comp = {"id": free_id(doc, ISO_ID), "type": "isosurface", "dataset": volume.dataset,
                        "visible": True, "opacity": 1.0, "transfer_function": None, "settings": settings}
                doc["components"].append(comp)
            comp["settings"]["styles"] = list(comp["settings"].get("styles") or []) + [new]

        if self.iso_component() is None and volume is None:
            return False
        return self._edit(change, f"Add the isosurface at {new['value']:g}")

    def edit(self, row: int, style: dict[str, Any]) -> bool:
        """Give surface ``row`` the value, colour and opacity of ``style``."""
        new = self._style(style)

        def change(doc: dict[str, Any]) -> None:
            comp = self._find(doc)
            if comp is not None and 0 <= row < len(comp["settings"].get("styles") or []):
                comp["settings"]["styles"][row] = new

        return self._edit(change, f"Edit the isosurface at {new['value']:g}")

    def remove(self, row: int) -> bool:
        """Remove surface ``row`` (the component with its last surface)."""
        def change(doc: dict[str, Any]) -> None:
            comp = self._find(doc)
            styles = list(comp["settings"].get("styles") or []) if comp is not None else []
            if not 0 <= row < len(styles):
                return
            del styles[row]
            comp["settings"]["styles"] = styles  # type: ignore[index]
            if not styles:
                doc["components"].remove(comp)

        return self._edit(change, "Remove an isosurface")

    def set_mode(self, mode: str) -> bool:
        """The isosurfaces' transparency mode (render option ``iso_mode``)."""
        def change(doc: dict[str, Any]) -> None:
            doc["render"].setdefault("options", {})["iso_mode"] = mode

        return self._edit(change, f"Isosurface transparency {mode}")
