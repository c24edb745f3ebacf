"""File > Show Another Array or Series…: for a file that holds several things to show (the datasets of an HDF5 file,
the variables of a MATLAB file, the series of a DICOM folder, the orbitals of a cube file, the levels of an OME-Zarr
image), the reader shows one and says which others there are
(``volviz.io.ChoiceWarning``, kept by ``read_notes`` while the scene loads); this dialog lists them, the shown one
selected, and shows the one picked: the dataset's reader option is set in the session (saved with it) and the scene
is loaded again (framed anew: the new choice may have other bounds). The component settings that named an array
of the old choice are cleared (the new choice has its own arrays)."""
from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Optional

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import (QDialog, QDialogButtonBox, QLabel, QListWidget, QListWidgetItem, QMenu, QVBoxLayout,
                               QWidget)

from volviz.io import ChoiceWarning


class FileChoiceDialog(QDialog):
    """The choices of one file (``choice.labels``), the shown one selected; ``picked()`` the value chosen."""

    def __init__(self, choice: ChoiceWarning, parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.choice = choice
        self.setWindowTitle(f"Show from {Path(choice.path).name}")
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel(f"{Path(choice.path).name} holds {len(choice.choices)} {_things(choice.option)}; "
                                "pick the one to show:"))
        self.list = QListWidget()
        for value, label in zip(choice.choices, choice.labels):
            item = QListWidgetItem(label)
            self.list.addItem(item)
            if value == choice.chosen:
                self.list.setCurrentItem(item)
        self.list.itemDoubleClicked.connect(lambda _item: self.accept())
        layout.addWidget(self.list)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(520, 320)

    def picked(self) -> Optional[str | int]:
        """The value of the item selected (a string or an integer, as the reader option takes it)."""
        row = self.list.currentRow()
        return self.choice.choices[row] if 0 <= row < len(self.choice.choices) else None


def _things(option: str) -> str:
    return {"series": "series", "variable": "variables", "dataset": "datasets", "orbital": "orbitals",
            "level": "levels"}.get(option, "arrays")


class FileChoices:
    """The File menu's action and the choices of the shown scene's files. ``window`` provides ``session``,
    ``session_path``, ``title``, ``dirty``, ``controller`` and ``_show_session``."""

    def __init__(self, window: Any, menu: QMenu) -> None:
        self.window = window
        self.choices: list[ChoiceWarning] = []
        self.dialog: Optional[FileChoiceDialog] = None
        self.action = menu.addAction("Show Another &Array or Series…")
        self.action.setShortcut("Ctrl+Alt+A")
        self.action.setEnabled(False)
        self.action.setToolTip("The file shown holds several arrays or series: pick the one to show")
        self.action.triggered.connect(self.ask)

    def set_choices(self, choices: list[ChoiceWarning]) -> None:
        """The shown scene's files' choices (one per file: the last said)."""
        by_file = {c.path: c for c in choices if len(c.choices) > 1 and c.option}
        self.choices = list(by_file.values())
        self.action.setEnabled(bool(self.choices))

    def hint(self) -> str:
        """The status bar's pointer to the action: ``"2 datasets: Ctrl+Alt+A shows another"``."""
        choice = self.choices[0]
        key = self.action.shortcut().toString(QKeySequence.SequenceFormat.NativeText)
        return f"{len(choice.choices)} {_things(choice.option)}: {key} shows another"

    def ask(self) -> None:
        """The dialog for the first file with choices (window-modal); its OK shows the one picked."""
        if not self.choices:
            return
        self.dialog = FileChoiceDialog(self.choices[0], self.window)
        self.dialog.setWindowModality(Qt.WindowModality.WindowModal)
        self.dialog.accepted.connect(lambda dialog=self.dialog: self.show(dialog.choice, dialog.picked()))
        self.dialog.open()

    def show(self, choice: ChoiceWarning, value: Optional[str | int]) -> bool:
        """Show ``value`` of ``choice``'s option (its file's dataset in the session); False when nothing changes."""
        from volviz.model.settings import array_key
        from volviz.session import resolve_path

        window = self.window
        if value is None or value == choice.chosen or value not in choice.choices:
            return False
        session = copy.deepcopy(window.session)
        target = Path(choice.path).resolve()

        def where(ref: Any) -> Path:       # as load_datasets reads it
            return resolve_path(window.session_path, ref.path) if window.session_path else Path(ref.path).resolve()

        refs = [ref for ref in session.datasets if where(ref) == target]
        if not refs:
            return False
        for ref in refs:
            ref.options[choice.option] = value
        ids = {ref.id for ref in refs}
        for comp in session.components:
            if comp.dataset in ids:
                comp.settings.pop(array_key(comp.type), None)
        window._show_session(session, window.session_path, window.title, dirty=True)
        return True
