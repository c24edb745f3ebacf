"""The viewport: its type, pyvistaqt's ``QtInteractor`` or the native-window ``NativeViewport`` (issue #28), and
which of them the window makes (``make_plotter``). Both are a pyvista plotter and a Qt widget (``interactor``), so the
window's parts use either through this one name, and mypy checks what they use on both. The Qt and VTK modules are
imported when a viewport is made: ``native_viewport`` sets VTK's Qt widget base on import."""
from __future__ import annotations

import logging
import os
from typing import TYPE_CHECKING, TypeAlias, Union

if TYPE_CHECKING:
    from PySide6.QtWidgets import QWidget
    from pyvistaqt import QtInteractor

    from .native_viewport import NativeViewport

log = logging.getLogger(__name__)

Viewport: TypeAlias = Union["QtInteractor", "NativeViewport"]


def viewport_kind(platform: str, setting: str) -> str:
    """Which viewport ``make_plotter`` makes: ``"native"`` (``NativeViewport``) on X11 (Qt's ``xcb`` platform) unless
    ``setting`` (``VOLVIZ_VIEWPORT``) is ``"qt"``; ``"qt"`` (pyvistaqt's ``QtInteractor``) there and everywhere else
    (Wayland, offscreen, Windows, macOS: a native GLX window needs X11, and pyvistaqt left native windows for Wayland,
    pyvistaqt gh-445). Another setting is named in a warning and gives the default."""
    if setting not in ("", "native", "qt"):
        log.warning("VOLVIZ_VIEWPORT=%r is neither 'native' nor 'qt': the default viewport is used", setting)
    return "native" if platform == "xcb" and setting != "qt" else "qt"


def make_plotter(parent: QWidget) -> Viewport:
    """The viewport (``viewport_kind``): on X11 the native-window ``NativeViewport``, which Qt does not compose, so a
    flight has fewer long event-loop stalls and more frames (issue #28, docs/bench/flight.md); with
    ``VOLVIZ_VIEWPORT=qt``, and off X11, pyvistaqt's ``QtInteractor``."""
    from PySide6.QtWidgets import QApplication
    from pyvistaqt import QtInteractor

    if viewport_kind(QApplication.platformName(), os.environ.get("VOLVIZ_VIEWPORT", "")) == "native":
        from .native_viewport import NativeViewport

        return NativeViewport(parent)
    return QtInteractor(parent, auto_update=False)  # we render when something changed, never on a timer
