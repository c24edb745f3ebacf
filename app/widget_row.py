"""A row of widgets side by side without margins: one form field of several values (x, y, z boxes, buttons)."""
from __future__ import annotations

from typing import Sequence

from PySide6.QtWidgets import QHBoxLayout, QWidget


def widget_row(widgets: Sequence[QWidget]) -> QWidget:
    """``widgets`` in one borderless horizontal row."""
    row = QWidget()
    layout = QHBoxLayout(row)
    layout.setContentsMargins(0, 0, 0, 0)
    for widget in widgets:
        layout.addWidget(widget)
    return row
