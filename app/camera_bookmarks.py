"""Camera bookmarks and camera-path recording of the main window: Camera > Add Bookmark…, Go to Bookmark and Record
Camera Path, kept in the shown scene's session. No numerics: the cameras come from the scene controller.

Held by the window as ``window.camera_bookmarks``; its collaborators are the shown scene (``shown_scene``), the
window as the parent of its dialog and timer, the status line, and two callbacks: ``edited()`` (the session changed:
the window marks it unsaved) and ``camera_moved()`` (a bookmark was gone to: the views follow)."""
from __future__ import annotations

import time
from typing import Callable, Optional

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QInputDialog, QLabel, QMenu, QWidget

from volviz.session import CameraKey
from .actions import menu_action
from .shown_scene import ShownScene

RECORD_MS = 250          # camera-path recording samples the camera four times a second


class CameraBookmarks:
    """Named camera views and recorded camera paths of the shown scene (see the module's docstring)."""

    def __init__(self, scene: ShownScene, parent: QWidget, status: QLabel, edited: Callable[[], None],
                 camera_moved: Callable[[], None]) -> None:
        self.scene, self.parent, self.status = scene, parent, status
        self.edited, self.camera_moved = edited, camera_moved
        self._recording: Optional[list[CameraKey]] = None  # the keys of the path being recorded (None: not recording)
        self._record_start = 0.0                             # when the recording started (``time.perf_counter``)
        self.record_timer = QTimer(parent, interval=RECORD_MS)   # samples the camera while recording
        self.record_timer.timeout.connect(self._record_sample)

    def add_to_menu(self, camera_menu: QMenu) -> None:
        """Camera > Add Bookmark… (Ctrl+B), Go to Bookmark (``bookmark_menu``) and Record Camera Path (Ctrl+R,
        ``action_record``)."""
        menu_action(self.parent, camera_menu, "Add &Bookmark…", "Ctrl+B", self.ask_bookmark)
        self.bookmark_menu = camera_menu.addMenu("Go to Bookmark")
        camera_menu.addSeparator()
        self.action_record = menu_action(self.parent, camera_menu, "&Record Camera Path", "Ctrl+R",
                                         self.set_recording)
        self.action_record.setCheckable(True)

    def add_bookmark(self, name: str) -> None:
        session, controller = self.scene.session, self.scene.controller
        if controller is None:
            return
        session.bookmarks[name] = controller.camera()
        self.refresh_menu()
        self.edited()

    def go_to_bookmark(self, name: str) -> None:
        session, controller = self.scene.session, self.scene.controller
        if controller is not None and name in session.bookmarks:
            controller.set_camera(session.bookmarks[name], update=False)
            self.camera_moved()

    def ask_bookmark(self) -> None:
        name, ok = QInputDialog.getText(self.parent, "Add bookmark", "Name:",
                                        text=f"view {len(self.scene.session.bookmarks) + 1}")
        if ok and name:
            self.add_bookmark(name)

    def refresh_menu(self) -> None:
        """Go to Bookmark lists the shown session's bookmarks (a new scene, a bookmark added)."""
        self.bookmark_menu.clear()
        bookmarks = self.scene.session.bookmarks
        for name in bookmarks:
            action = self.bookmark_menu.addAction(name)
            action.triggered.connect(lambda checked=False, n=name: self.go_to_bookmark(n))
        self.bookmark_menu.setEnabled(bool(bookmarks))

    def set_recording(self, recording: bool) -> Optional[str]:
        """Start or stop recording a camera path; stopping stores it in the session and returns its name."""
        self.action_record.setChecked(recording)
        if recording and self.scene.controller is not None:
            self._recording = []
            self._record_start = time.perf_counter()
            self._record_sample()
            self.record_timer.start()
            self.status.setText("Recording camera path…")
            return None
        self.record_timer.stop()
        keys, self._recording = self._recording, None
        if not keys:
            return None
        self._record_sample_into(keys)
        if len(keys) < 2:
            return None
        paths = self.scene.session.camera_paths
        name = f"path {len(paths) + 1}"
        paths[name] = keys
        self.edited()
        self.status.setText(f"Recorded camera path {name!r} ({len(keys)} keys, {keys[-1].time:.1f} s)")
        return name

    def stop(self) -> None:
        """The window closes: no more samples."""
        self.record_timer.stop()

    def _record_sample(self) -> None:
        if self._recording is not None:
            self._record_sample_into(self._recording)

    def _record_sample_into(self, keys: list[CameraKey]) -> None:
        controller = self.scene.controller
        if controller is None:
            return
        t = time.perf_counter() - self._record_start
        cam = controller.camera()
        if keys and (t <= keys[-1].time or cam == keys[-1].camera):
            return
        keys.append(CameraKey(t, cam))
