"""Camera bookmarks and camera-path recording of the main window (a mixin of ``MainWindow``: it uses the window's
session, controller, menus, timer and status bar). No numerics: the cameras come from the scene controller."""
from __future__ import annotations

import time
from typing import Optional

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QInputDialog

from volviz.session import CameraKey
from .window_base import WindowBase


class CameraBookmarks(WindowBase):
    """Named camera views (Camera > Bookmarks) and recorded camera paths (Camera > Record Path), kept in the
    session."""

    _recording: Optional[list[CameraKey]]  # the keys of the path being recorded (None: not recording)
    _record_start: float                   # when the recording started (``time.perf_counter``)
    record_timer: QTimer                   # samples the camera while recording (made by the window's ``__init__``)

    def add_bookmark(self, name: str) -> None:
        if self.controller is None:
            return
        self.session.bookmarks[name] = self.controller.camera()
        self._refresh_bookmark_menu()
        self.set_dirty()

    def go_to_bookmark(self, name: str) -> None:
        if self.controller is not None and name in self.session.bookmarks:
            self.controller.set_camera(self.session.bookmarks[name], update=False)
            self._camera_moved()

    def _ask_bookmark(self) -> None:
        name, ok = QInputDialog.getText(self, "Add bookmark", "Name:", text=f"view {len(self.session.bookmarks) + 1}")
        if ok and name:
            self.add_bookmark(name)

    def _refresh_bookmark_menu(self) -> None:
        self.bookmark_menu.clear()
        for name in self.session.bookmarks:
            action = self.bookmark_menu.addAction(name)
            action.triggered.connect(lambda checked=False, n=name: self.go_to_bookmark(n))
        self.bookmark_menu.setEnabled(bool(self.session.bookmarks))

    def set_recording(self, recording: bool) -> Optional[str]:
        """Start or stop recording a camera path; stopping stores it in the session and returns its name."""
        self.action_record.setChecked(recording)
        if recording and self.controller is not None:
            self._recording = []
            self._record_start = time.perf_counter()
            self._record_sample()
            self.record_timer.start()
            self.status_label.setText("Recording camera path…")
            return None
        self.record_timer.stop()
        keys, self._recording = self._recording, None
        if not keys:
            return None
        self._record_sample_into(keys)
        if len(keys) < 2:
            return None
        name = f"path {len(self.session.camera_paths) + 1}"
        self.session.camera_paths[name] = keys
        self.set_dirty()
        self.status_label.setText(f"Recorded camera path {name!r} ({len(keys)} keys, {keys[-1].time:.1f} s)")
        return name

    def _record_sample(self) -> None:
        if self._recording is not None:
            self._record_sample_into(self._recording)

    def _record_sample_into(self, keys: list[CameraKey]) -> None:
        if self.controller is None:
            return
        t = time.perf_counter() - self._record_start
        cam = self.controller.camera()
        if keys and (t <= keys[-1].time or cam == keys[-1].camera):
            return
        keys.append(CameraKey(t, cam))
