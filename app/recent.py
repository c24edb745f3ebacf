"""File > Open Recent and the folder the open dialogs start in, both kept in ``QSettings`` between launches.

A file joins the list only once it has opened (the window calls ``add`` when the scene is shown, never when the open
starts), and files that have since disappeared are dropped whenever the menu is filled.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QMenu

MAX_RECENT = 8
RECENT_KEY = "recent_files"
FOLDER_KEY = "last_folder"


class RecentFiles:
    """The recent files of ``settings``, shown in ``menu``; choosing one calls ``open_path(path)``."""

    def __init__(self, settings: QSettings, menu: QMenu, open_path: Callable[[str], None]) -> None:
        self.settings, self.menu, self.open_path = settings, menu, open_path
        self.refresh()

    def files(self) -> list[str]:
        """The recent files that still exist, newest first."""
        value = self.settings.value(RECENT_KEY, [])
        entries = [value] if isinstance(value, str) else value if isinstance(value, (list, tuple)) else []
        return [str(v) for v in entries if os.path.exists(str(v))]

    def add(self, path: str | os.PathLike) -> None:
        """``path`` opened: it goes to the top of the list, and its folder is where the next dialog starts."""
        entry = str(Path(path).resolve())
        files = [entry] + [f for f in self.files() if f != entry]
        self.settings.setValue(RECENT_KEY, files[:MAX_RECENT])
        self.remember_folder(entry)
        self.refresh()

    def refresh(self) -> None:
        """Fill the menu (the missing files are dropped from the stored list too)."""
        files = self.files()
        self.settings.setValue(RECENT_KEY, files)
        self.menu.clear()
        for f in files:
            action = self.menu.addAction(f)
            action.setToolTip(f"Open {f}")
            action.triggered.connect(lambda checked=False, p=f: self.open_path(p))
        self.menu.setEnabled(bool(files))

    def last_folder(self) -> str:
        """Where an open or save dialog starts: the folder used last (if it still exists), else the home folder."""
        folder = str(self.settings.value(FOLDER_KEY, "") or "")
        return folder if folder and os.path.isdir(folder) else str(Path.home())

    def remember_folder(self, path: str | os.PathLike) -> None:
        """A file (or folder) was chosen in a dialog or opened: its folder is where the next dialog starts."""
        p = Path(path)
        self.settings.setValue(FOLDER_KEY, str(p if p.is_dir() else p.parent))
