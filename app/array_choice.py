"""The array selector of the scene tree: which array of its dataset the selected component shows.

The choices are ``volviz.model.arrays.list_arrays``'s (a scalar array by name; a vector or tensor array as its
magnitude or one component; a name on both the points and the cells once for each, "p (points)" and "p (cells)",
the cell one's spec ``p@cells``). A choice is one undoable step on the window's undo stack
(``volviz_app.component_settings``); it sets the component setting ``"array"`` (saved with the session) and
re-prepares the component through the window's settings path (``apply_component_settings``), which keeps the camera
and the docks as they are."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QComboBox

from .component_settings import edit_settings


def choice_label(spec: str, association: str, shared: bool) -> str:
    """The combo's text of ``spec``: the spec itself, and for a name on both the points and the cells its association
    in words, as ParaView's list tells them apart ("p (points)", "U:0 (cells)"), never the spec's ``@cells``."""
    from dataclasses import replace

    from volviz.model.arrays import parse_array_spec

    if not shared:
        return spec
    return f"{replace(parse_array_spec(spec), association=None)} ({association}s)"


def offered_spec(spec: str, infos: list[Any]) -> str:
    """The choice of ``infos`` (``list_arrays``'s) that names the same array and component as ``spec`` (a session may
    say ``p@points``, or ``V`` for a vector's magnitude, where the list offers ``p`` and ``V:magnitude``); ``spec``
    itself when none does (an array the dataset lacks: still listed, so the setting shows)."""
    from volviz.model.arrays import MAGNITUDE, parse_array_spec

    wanted = parse_array_spec(spec)
    for info in infos:
        if wanted.matches(info.name, info.association):
            for choice in info.choices:
                component = parse_array_spec(choice).component
                if component == wanted.component or (wanted.component is None and component == MAGNITUDE):
                    return choice
            return spec
    return spec


class ArrayChoice:
    """Fills ``combo`` for the component the scene tree selects and turns a user's choice into an undoable settings
    edit on ``undo_stack``. ``window`` provides ``controller``, ``session`` and ``apply_component_settings``."""

    def __init__(self, window: Any, combo: QComboBox, undo_stack: QUndoStack) -> None:
        self.window, self.combo, self.undo_stack = window, combo, undo_stack
        self.comp_id: Optional[str] = None
        self.shown: Optional[str] = None   # the spec the selected component shows
        combo.setToolTip("The array the selected component shows: a scalar array, or a vector array's magnitude or "
                         "one of its components (point and cell arrays of the dataset)")
        combo.setEnabled(False)
        combo.activated.connect(self._chosen)

    def current(self, comp_id: str) -> Optional[str]:
        """The array spec the component's settings name (None: the dataset's default)."""
        from volviz.model.settings import array_key

        comp = self.window.controller.component(comp_id)
        value = comp.settings.get(array_key(comp.type))
        return str(value) if value else None

    def show_component(self, comp_id: Optional[str]) -> None:
        """List the arrays of ``comp_id``'s dataset (nothing for a component without one, e.g. the sky)."""
        from volviz.model.arrays import default_array, list_arrays

        self.comp_id, self.shown = comp_id, None
        self.combo.clear()
        controller = self.window.controller
        infos, shown = [], None
        if comp_id is not None and controller is not None and controller.component(comp_id).dataset is not None:
            dataset = controller.datasets.get(controller.component(comp_id).dataset)
            if dataset is not None:  # (a hidden component's dataset is read when it is shown)
                infos = list_arrays(dataset)
                self.shown = shown = self.current(comp_id) or default_array(dataset)
        names = [info.name for info in infos]
        for info in infos:
            for spec in info.choices:
                lo, hi = info.range
                bad = f", {info.nonfinite:,} non-finite" if info.nonfinite else ""
                self.combo.addItem(choice_label(spec, info.association, names.count(info.name) > 1), spec)
                self.combo.setItemData(self.combo.count() - 1, f"{info.association} array, range {lo:.4g} … "
                                       f"{hi:.4g}{bad}", Qt.ItemDataRole.ToolTipRole)
        if shown is not None and self.combo.findData(shown) < 0:
            shown = offered_spec(shown, infos)   # "p@points" where the list says "p"
        if shown is not None and self.combo.findData(shown) < 0:
            self.combo.addItem(shown, shown)
        self.combo.setCurrentIndex(max(self.combo.findData(shown), 0) if shown is not None else -1)
        self.combo.setEnabled(self.combo.count() > 1)

    def choose(self, spec: str) -> None:
        """The user picked ``spec`` for the selected component: one undoable step (nothing if it is shown now)."""
        comp_id = self.comp_id
        if comp_id is None or self.window.controller is None or spec == self.shown:
            return
        from volviz.model.settings import array_key

        comp = self.window.controller.component(comp_id)
        before = dict(comp.settings)
        edit_settings(self.window, self.undo_stack, comp_id, before, {**before, array_key(comp.type): spec},
                      f"Show {spec} in {comp_id}")

    def names(self, comp_id: str) -> list[str]:
        """The names of the arrays of ``comp_id``'s dataset (none while it is not read, or without a dataset)."""
        from volviz.model.arrays import list_arrays

        controller = self.window.controller
        if controller is None or controller.component(comp_id).dataset is None:
            return []
        dataset = controller.datasets.get(controller.component(comp_id).dataset)
        return [] if dataset is None else [info.name for info in list_arrays(dataset)]

    def _chosen(self, index: int) -> None:
        spec = self.combo.itemData(index)
        if spec is not None:
            self.choose(str(spec))
