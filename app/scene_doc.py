"""Undoable edits of the scene's document: components added or removed, the render options (the slices and
isosurface docks).

An edit changes a copy of the session document (``volviz.session.session_to_dict``) and shows it through the session
loader (validated; a bad document gives a message naming the problem and changes nothing) with the same camera and
docks, rebuilt in the background like a settings edit (``volviz_app.component_settings``). Only the document's
``components`` and ``render`` parts are kept for undo: Edit > Undo puts those back on the current document, so the
transfer-function and clipping stacks' edits made since stay.
"""
from __future__ import annotations

import copy
from typing import Any, Callable

from PySide6.QtGui import QUndoCommand, QUndoStack

PARTS = ("components", "render")


def current_document(window: Any) -> dict[str, Any]:
    """The shown session as a document (the window's camera)."""
    from volviz.session import session_to_dict

    return session_to_dict(window.session)


def apply_parts(window: Any, parts: dict[str, Any]) -> bool:
    """Show the current document with ``parts`` (a subset of ``PARTS``) replaced; False (and a message) when the
    session loader refuses it."""
    from volviz.session import SessionError, session_from_dict

    if window.controller is None:
        return False
    doc = current_document(window)
    doc.update(copy.deepcopy(parts))
    try:
        candidate = session_from_dict(doc, "scene")
    except (ValueError, SessionError) as exc:
        window.show_error("Invalid scene", str(exc))
        return False
    candidate.camera = window.controller.camera()
    candidate.layout.pop("window_state", None)  # the docks stay where they are
    window._show_session(candidate, window.session_path, getattr(window, "title", ""), True, datasets=window.datasets)
    return True


class EditDocument(QUndoCommand):
    """The document's ``PARTS`` from ``before`` to ``after`` (``after`` is shown already when pushed)."""

    def __init__(self, window: Any, before: dict[str, Any], after: dict[str, Any], text: str) -> None:
        super().__init__(text)
        self.window, self.before, self.after = window, before, after
        self.applied = True

    def redo(self) -> None:
        if self.applied:
            self.applied = False
            return
        apply_parts(self.window, self.after)

    def undo(self) -> None:
        apply_parts(self.window, self.before)


def edit_document(window: Any, undo_stack: QUndoStack, change: Callable[[dict[str, Any]], None], text: str) -> bool:
    """Apply ``change`` (it edits a document in place) to the shown document and, when the loader accepts the result,
    push it on ``undo_stack``. Nothing happens when ``change`` changes nothing."""
    if window.controller is None:
        return False
    doc = current_document(window)
    before = {key: copy.deepcopy(doc[key]) for key in PARTS}
    change(doc)
    after = {key: copy.deepcopy(doc[key]) for key in PARTS}
    if after == before or not apply_parts(window, after):
        return False
    undo_stack.push(EditDocument(window, before, after, text))
    return True


def free_id(doc: dict[str, Any], base: str) -> str:
    """``base``, primed until no component of ``doc`` has it."""
    taken = {c["id"] for c in doc["components"]}
    name = base
    while name in taken:
        name += "'"
    return name
