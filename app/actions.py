"""A menu entry: a ``QAction`` with its shortcut and slot, added to a menu (the window's menus and the parts that
add their own entries, ``camera_bookmarks``, use it alike)."""
from __future__ import annotations

from typing import Any

from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMenu, QWidget


def menu_action(parent: QWidget, menu: QMenu, text: str, shortcut: Any, slot: Any) -> QAction:
    """``text`` in ``menu`` with ``shortcut`` (a ``QKeySequence`` key or string; "" for none), ``triggered`` to
    ``slot``; ``parent`` owns the action."""
    action = QAction(text, parent)
    action.setShortcut(QKeySequence(shortcut))
    action.triggered.connect(slot)
    menu.addAction(action)
    return action
