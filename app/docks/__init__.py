"""Dock widgets of the main window."""

from typing import Any


def set_tooltips(*pairs: tuple[Any, str]) -> None:
    """Give each widget its tooltip: ``set_tooltips((button, "what it does"), ...)``."""
    for widget, tip in pairs:
        widget.setToolTip(tip)
