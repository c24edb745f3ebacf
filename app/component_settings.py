"""Undoable edits of a component's settings (the scene tree's settings form, the array combo box).

An edit is applied through the window's settings path (``apply_component_settings``: validated through the session
loader, the scene rebuilt in the background with the same camera and docks, the session marked dirty) and, once
accepted, pushed on the window's scene undo stack, so that Edit > Undo / Redo apply the settings before / after it.
"""
from __future__ import annotations

import copy
from typing import Any, Optional

from PySide6.QtGui import QUndoCommand, QUndoStack


class SetSettings(QUndoCommand):
    """Component ``comp_id``'s settings from ``before`` to ``after``. With ``applied`` the window shows ``after``
    already: the push does nothing more; every later redo or undo applies ``after`` or ``before``."""

    def __init__(self, window: Any, comp_id: str, before: dict[str, Any], after: dict[str, Any], text: str,
                 applied: bool = False) -> None:
        super().__init__(text)
        self.window, self.comp_id, self.applied = window, comp_id, applied
        self.before, self.after = copy.deepcopy(before), copy.deepcopy(after)

    def redo(self) -> None:
        if self.applied:
            self.applied = False
            return
        self.window.apply_component_settings(self.comp_id, copy.deepcopy(self.after))

    def undo(self) -> None:
        self.window.apply_component_settings(self.comp_id, copy.deepcopy(self.before))


def edit_settings(window: Any, undo_stack: QUndoStack, comp_id: str, before: dict[str, Any], after: dict[str, Any],
                  text: Optional[str] = None) -> bool:
    """Apply ``after`` as component ``comp_id``'s settings (``window.apply_component_settings``) and, if the window
    accepted them, push the edit on ``undo_stack``. Nothing happens when ``after`` equals ``before``."""
    if after == before or not window.apply_component_settings(comp_id, copy.deepcopy(after)):
        return False
    undo_stack.push(SetSettings(window, comp_id, before, after, text or f"Edit the settings of {comp_id}",
                                applied=True))
    return True
