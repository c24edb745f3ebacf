"""An undo step for an edit the window shows before it is pushed (a slice moved, the scalar bar restyled): the push
itself does nothing; every later redo or undo shows the state after or before the edit through one function."""
from __future__ import annotations

import copy
from typing import Any, Callable

from PySide6.QtGui import QUndoCommand


class ShownEdit(QUndoCommand):
    """``show(before)`` on undo, ``show(after)`` on a redo after the first (deep copies of both are kept)."""

    def __init__(self, text: str, before: Any, after: Any, show: Callable[[Any], None]) -> None:
        super().__init__(text)
        self.before, self.after, self.show = copy.deepcopy(before), copy.deepcopy(after), show
        self.applied = True

    def redo(self) -> None:
        if self.applied:
            self.applied = False
            return
        self.show(copy.deepcopy(self.after))

    def undo(self) -> None:
        self.show(copy.deepcopy(self.before))
