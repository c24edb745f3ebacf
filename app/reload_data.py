"""File > Reload Data (F5): read the shown scene's files again — a solver or a script rewrote them — and show them
as they are now, keeping the view: the camera, the display time, the transfer functions, the component settings and
whether the session has unsaved changes. The scene shown stays until the new read is ready, and stays on when it
fails (``SceneLoading._show_session``)."""
from __future__ import annotations

import copy
from typing import Any

from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMenu


class ReloadData:
    """The File menu's action. ``window`` provides ``session``, ``session_path``, ``title``, ``dirty``,
    ``controller`` and ``_show_session``."""

    def __init__(self, window: Any, menu: QMenu) -> None:
        self.window = window
        self.action = QAction("&Reload Data", window)
        self.action.setShortcut(QKeySequence("F5"))      # not the standard Refresh: Ctrl+R records a camera path
        self.action.setToolTip("Read the shown files again (after a solver or a script rewrote them), keeping the view")
        self.action.triggered.connect(self.reload)
        menu.addAction(self.action)

    def reload(self) -> bool:
        """Read the datasets again and show the scene with the current camera and time; False when nothing is shown
        or the scene reads no file."""
        window = self.window
        controller = window.controller
        if controller is None or not window.session.datasets:
            return False
        session = copy.deepcopy(window.session)
        session.camera = controller.camera()
        if controller.time_series():
            session.render.options["time"] = float(controller.time)
        window._show_session(session, window.session_path, window.title, dirty=window.dirty)
        return True
