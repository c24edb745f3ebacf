"""View > Scalar Bar, Orientation Axes and Outline Box: checkable actions for the decorations volviz draws around
the data (``volviz.render.decorations``). Each is a render option of the session (``scalar_bar``, ``axes``,
``outline``; on unless false), so the choice is saved with the session and comes back with it."""
from __future__ import annotations

from typing import Any

from PySide6.QtGui import QAction
from PySide6.QtWidgets import QMenu

TOGGLES = (("scalar_bar", "Scalar &Bar", "The color legend of the shown array, with its name and range"),
           ("axes", "Orientation &Axes", "The x, y, z axes in the corner of the viewport"),
           ("outline", "&Outline Box", "The box around the data"))


class DecorationToggles:
    """The three actions in ``menu``; ``window`` provides ``session``, ``controller``, ``set_dirty`` and
    ``render_scene``. ``actions`` maps each render option to its action."""

    def __init__(self, window: Any, menu: QMenu) -> None:
        self.window = window
        self.actions: dict[str, QAction] = {}
        for key, text, tip in TOGGLES:
            action = QAction(text, window)
            action.setCheckable(True)
            action.setChecked(True)
            action.setToolTip(tip)
            action.setStatusTip(tip)
            action.toggled.connect(lambda on, k=key: self.set(k, on))
            menu.addAction(action)
            self.actions[key] = action

    def sync(self) -> None:
        """Show the session's options (a scene was opened); nothing is redrawn."""
        from volviz.render.decorations import decoration_enabled

        for key, action in self.actions.items():
            action.blockSignals(True)
            action.setChecked(decoration_enabled(self.window.session, key))
            action.blockSignals(False)

    def set(self, key: str, on: bool) -> None:
        """Switch the decoration ``key`` on or off in the session and on screen."""
        window = self.window
        if bool(window.session.render.options.get(key, True)) == on:
            return
        window.session.render.options[key] = bool(on)
        window.set_dirty()
        if window.controller is not None:
            window.controller.decorate()
            window.render_scene()
