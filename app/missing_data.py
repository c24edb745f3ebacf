"""A session whose data files are not where it says: find them in the folders the user located before (remembered
in the settings) and in ``$VOLVIZ_DATA``; for those still missing, a dialog names each file and offers to locate the
folder that holds them (searched with ``volviz.session.locate_missing`` and remembered). The shown scene stays until
every file is found; Cancel keeps it."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable, Optional

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QFileDialog, QLabel, QListWidget, QVBoxLayout, QWidget

from volviz.session import MissingFile, Session, locate_missing, missing_files, unset_variables

FOLDERS_KEY = "data/folders"   # the folders the user located data in, newest first
MAX_FOLDERS = 8


def remembered_folders(settings: QSettings) -> list[Path]:
    """Where to look first: the folders located before, then ``$VOLVIZ_DATA`` when it is set."""
    value: Any = settings.value(FOLDERS_KEY, [])
    stored = [value] if isinstance(value, str) else list(value) if isinstance(value, (list, tuple)) else []
    folders = [Path(str(v)) for v in stored if v]
    env = os.environ.get("VOLVIZ_DATA")
    return [f for f in folders + ([Path(env)] if env else []) if f.is_dir()]


def remember_folder(settings: QSettings, folder: Path) -> None:
    kept = [str(folder)] + [str(f) for f in remembered_folders(settings) if f != folder]
    settings.setValue(FOLDERS_KEY, kept[:MAX_FOLDERS])


def apply_found(session: Session, found: dict[str, Path]) -> None:
    """Point the session's datasets at the files found (absolute paths: saving makes them relative again)."""
    for ref in session.datasets:
        if ref.id in found:
            ref.path = str(found[ref.id])


def still_missing(session: Session, session_file: Optional[Path], settings: QSettings) -> list[MissingFile]:
    """The session's missing files after looking in the remembered folders (the session is updated for the found)."""
    missing = missing_files(session, session_file)
    if missing:
        apply_found(session, locate_missing(missing, remembered_folders(settings)))
        missing = missing_files(session, session_file)
    return missing


class MissingDataDialog(QDialog):
    """Names each missing file; Locate Folder… searches a folder the user picks (remembered) and calls
    ``on_complete(session)`` once every file is found; Cancel changes nothing."""

    def __init__(self, session: Session, session_file: Optional[Path], missing: list[MissingFile],
                 settings: QSettings, on_complete: Callable[[Session], Any], parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.session, self.session_file, self.missing = session, session_file, missing
        self.settings, self.on_complete = settings, on_complete
        self.folder_dialog: Optional[QFileDialog] = None
        name = session_file.name if session_file is not None else "The session"
        self.setWindowTitle("Data files not found")
        self.label = QLabel()
        self.label.setWordWrap(True)
        self.files = QListWidget()
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Cancel)
        self.locate_button = buttons.addButton("Locate Folder…", QDialogButtonBox.ButtonRole.ActionRole)
        self.locate_button.clicked.connect(self.ask_folder)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.label)
        layout.addWidget(self.files)
        layout.addWidget(buttons)
        self._name = name
        self._show_missing()

    def _show_missing(self) -> None:
        unset = unset_variables(self.missing)
        where = (f" It finds them through {', '.join('$' + v for v in unset)}, which is not set: locate the folder "
                 "that holds them (for the shipped example sessions, volviz's test data folder, shared/data), or "
                 f"set {', '.join(unset)} and open it again." if unset else
                 " Locate the folder that holds them; it is searched, and remembered for next time.")
        self.label.setText(f"{self._name} needs {len(self.missing)} data file{'s' if len(self.missing) > 1 else ''} "
                           f"that {'are' if len(self.missing) > 1 else 'is'} not where it says.{where} "
                           "The scene shown now stays until they are found.")
        self.files.clear()
        for f in self.missing:
            self.files.addItem(f"{f.dataset}: {f.stored}")

    def ask_folder(self) -> None:
        dialog = QFileDialog(self, "The folder that holds the data files")
        dialog.setOption(QFileDialog.Option.DontUseNativeDialog, True)
        dialog.setFileMode(QFileDialog.FileMode.Directory)
        dialog.setOption(QFileDialog.Option.ShowDirsOnly, True)
        dialog.fileSelected.connect(lambda path: self.search(Path(path)))
        dialog.open()
        self.folder_dialog = dialog

    def search(self, folder: Path) -> None:
        """Look for the missing files under ``folder``; done when none is left."""
        found = locate_missing(self.missing, [folder])
        if found:
            remember_folder(self.settings, folder)
            apply_found(self.session, found)
        self.missing = missing_files(self.session, self.session_file)
        if not self.missing:
            self.accept()
            self.on_complete(self.session)
            return
        self._show_missing()
